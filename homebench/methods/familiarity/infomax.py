"""Infomax route navigation (Baddeley, Graham, Husbands & Philippides 2012, PLoS Comput. Biol.
8(1): e1002336): a network trained on the route's views tells how familiar a view looks.

Model: a single layer of ``H`` novelty units fully connected to the ``N`` pixels of the
down-sampled view ``x`` (grey levels in [0, 1]). Activations ``h = W x``, outputs
``y = tanh(h)``. Each training view (route order, each facing the way the route runs) is
presented once and changes the weights by the Infomax rule (Bell & Sejnowski 1995, in the
natural-gradient form the paper uses)::

    W <- W + (eta / N) * (W - (y + h) (h^T W))

which decorrelates the units' responses to the training views: a familiar view drives them
little. The familiarity measure is the summed absolute activation ``sum_i |h_i|``, lower is more
familiar; the agent turns its view through every column shift and heads in the direction of
the smallest (protocol and conventions: :mod:`homebench.methods.familiarity.route_memory`).

The reference: the paper's own text was out of reach here, so the defaults follow the authors'
MATLAB code (``infomax_train.m``, ``infomax_init2.m``, kept in the Brains on Board robotics
repository under ``examples/infomax/matlab``): the rule above with ``eta = 0.001`` and the
update scaled by ``1 / N``, N the input pixels (``infomax_learn2``: ``eta / N`` times
``(I - (y + h) h^T) W``), the familiarity ``sum |h|``, as many novelty units as pixels, one
presentation per view, pixels scaled to [0, 1], and initial weights drawn from a standard
normal distribution, then each input's weights over the units shifted and scaled to mean 0 and
SD 1. Brains on Board's C++ ``InfoMax`` (include/navigation/infomax.h) agrees except for the
step: since August 2023 it scales the update by ``1 / (N H)`` ("additional scaling after M from
Azevedo et al. 2023") with a learning rate of 0.97, an effective step of ``0.97 / N**2`` at
``H = N``, about 0.63 times the MATLAB code's ``0.001 / N`` at 90 x 17 pixels. That step, and
homebench's earlier uniform per-unit initial weights, are options (``learning_rate_scaling``,
``init``); BoB's reading is ``learning_rate: 0.97, learning_rate_scaling: per-input-and-unit``.
Weights that grow without bound (a learning rate too large for the views) raise a ValueError
naming the rate (the MATLAB code instead lowers the rate by 1 % and retrains until they do
not).

Validation (tests/test_validation_route_memory.py), on the scene of
:mod:`~homebench.methods.familiarity.perfect_memory`'s validation, whose views have far less
contrast than
the paper's silhouettes against the sky (grey-level SD about 0.09 at 90 x 17): at the
defaults the network learns the route's 2 m first leg (20 of its 31 views) and hardly its 1 m
second leg; on that leg and at the corner every probe but one heads along the first leg (90 deg
off), so 50-57 % of the probes are within 45 deg at each distance, the median error is 1.2 deg
on the route and 2.2 deg 0.25 m beside it, and the catchment is 0.25 m. With ``standardize``:
median heading error 0.7-1.9 deg at every distance up to 1 m from the route, 86-100 % of
probes within 45 deg (perfect memory: 86-100 %), catchment the 1 m tested. (homebench's
earlier defaults, ``learning_rate`` 0.01 and ``init`` uniform: 1.0-2.4 deg, 71-86 %, 1 m.)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field

from homebench.errors import ConfigError
from homebench.methods.base import ImageKind, is_flat
from homebench.methods.familiarity.route_memory import FloatArray, RouteMemory, rotations
from homebench.methods.params import documented, param
from homebench.methods.registry import register

LearningRateScaling = Literal["per-input", "per-input-and-unit"]
InitialWeights = Literal["normal", "uniform"]


@register
@documented
@dataclass(frozen=True)
class Infomax(RouteMemory):
    """Infomax (Baddeley et al. 2012): a network trained on the route's views by the Infomax
    rule; the heading is the rotation with the smallest summed absolute activation."""

    name: ClassVar[str] = "infomax"
    image_kind: ClassVar[ImageKind] = "unfolded"

    learning_rate: float = param(
        0.001,
        "eta of the Infomax rule (the update is scaled by eta / N, or eta / (N * H) with "
        "learning_rate_scaling per-input-and-unit; N the view's pixels, H the novelty units).",
        reading="the paper's value could not be checked here; 0.001 is the authors' MATLAB "
        "code's (infomax_train.m: 'mu=0.001', applied as lrate/N). Brains on Board's C++ "
        "InfoMax defaults to 0.97 with the update scaled by 1 / (N H) (DefaultLearningRate, "
        "include/navigation/infomax.h, since August 2023): use learning_rate 0.97 with "
        "learning_rate_scaling per-input-and-unit for its reading. homebench's default was 0.01 "
        "before, ten times the authors' code",
    )
    learning_rate_scaling: LearningRateScaling = param(
        "per-input",
        "How eta is scaled in each update: per-input, eta / N; per-input-and-unit, eta / (N * H).",
        paper="the authors' MATLAB code divides eta by N, the number of input pixels "
        "(infomax_learn2 in infomax_train.m: 'lrate/N', N = size(patts,1)). "
        "per-input-and-unit is Brains on Board's C++ InfoMax since August 2023 "
        "('m_LearningRate / (numInputs * numHidden)', after Azevedo et al. 2023), made for its "
        "learning rate 0.97: it makes each step H times smaller than per-input at the same eta "
        "(at the default H = N, BoB's 0.97 / N**2 is 0.63 times the MATLAB code's 0.001 / N "
        "for 90 x 17 views)",
    )
    epochs: int = param(
        1,
        "Presentations of the whole training route (route order each time).",
        reading="one pass, each view presented once, as the authors' code trains",
    )
    hidden_units: int | None = param(
        None,
        "Novelty units H (at least 2 with init normal, whose normalisation is over the units); "
        "None: as many as the view has pixels.",
        reading="as many units as pixels, as the authors' code comments say is normal",
    )
    init: InitialWeights = param(
        "normal",
        "Initial weights (H, N): normal, standard normal draws, then each input's weights "
        "(a column, over the H units) shifted and scaled to mean 0 and SD 1; uniform, draws "
        "uniform in [-0.5, 0.5], then each unit's weights (a row, over the N inputs) shifted "
        "and scaled to mean 0 and SD 1 (the SD as the root mean square deviation, not the sample "
        "SD).",
        paper="the authors' MATLAB code draws standard normal weights and normalises each "
        "input's weights over the units (infomax_init2.m: w = randn(V,H), less mean(w,2), "
        "over std(w,1,2); the network takes its transpose, H x V), and Brains on Board's C++ "
        "InfoMax does the same (generateInitialWeights: normal draws, rows of its inputs x "
        "hidden matrix normalised, then transposed). uniform is homebench's earlier reading, "
        "no reference's, kept to reproduce earlier results: each unit's weights then sum to "
        "0, so no unit responds to a view's mean grey level",
    )
    standardize: bool = param(
        False,
        "Give the network each view at zero mean and unit standard deviation (its grey levels "
        "shifted and scaled).",
        paper="the network takes the pixels as grey levels in [0, 1], as the authors' code "
        "does (Brains on Board's InfoMax offers z-scored views too, Normalisation::ZScore, off "
        "by default). How much a view changes the weights grows with its contrast, so a "
        "learning rate suits one kind of scene; the paper's views are silhouettes against the "
        "sky. At the authors' rate the validation route's outdoor views (grey-level SD about "
        "0.09 at 90 x 17) teach the network the route's longer leg only (catchment 0.25 m; "
        "standardized: 1 m, median heading error 0.7-1.9 deg), and a one-view memory in the "
        "posters room is a compass to a median 4.1 deg (30 pairs of grid neighbours 0.3 m "
        "apart, the current view at a random heading: 70 % within 10 deg; standardized: 1.1 "
        "deg, all within 10 deg). Learning a view changes its activations h by about "
        "eta / N * |h|**2 times themselves: 0.29 for the first of those outdoor views as they "
        "are, 1.5 standardized (|h|**2 about N**2 at H = N), so standardized views larger than "
        "90 x 17 need a smaller eta",
    )
    seed: Annotated[int, Field(ge=0)] = param(
        0,
        "Seed of the initial weights (see init).",
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.learning_rate <= 0 or self.epochs < 1:
            raise ConfigError("infomax: learning_rate must be positive and epochs at least 1")
        if self.hidden_units is not None and self.hidden_units < 1:
            raise ConfigError("infomax: hidden_units must be at least 1 or null")
        if self.init == "normal" and self.hidden_units == 1:
            raise ConfigError(
                "infomax: init normal normalises each input's weights over the units: "
                "hidden_units must be at least 2 (or null)"
            )

    def standardized(self, view: FloatArray) -> FloatArray:
        """The view (rows, columns) as the network takes it: as described, or with
        ``standardize`` at zero mean and unit standard deviation (a flat view: zeros)."""
        if not self.standardize:
            return view
        return np.zeros_like(view) if is_flat(view) else (view - np.mean(view)) / np.std(view)

    def start_weights(self, n_inputs: int) -> FloatArray:
        """Initial weights (H, n_inputs), seeded: see ``init``."""
        units = self.hidden_units or n_inputs
        rng = np.random.default_rng(self.seed)
        if self.init == "uniform":
            weights = rng.uniform(-0.5, 0.5, (units, n_inputs))
            axis = 1  # each unit's weights
        else:
            weights = rng.standard_normal((units, n_inputs))
            axis = 0  # each input's weights, over the units
        weights -= weights.mean(axis=axis, keepdims=True)
        return weights / weights.std(axis=axis, keepdims=True)

    def step_size(self, n_inputs: int, n_units: int) -> float:
        """The factor of each update: eta / N, or eta / (N * H) (``learning_rate_scaling``)."""
        if self.learning_rate_scaling == "per-input-and-unit":
            return self.learning_rate / (n_inputs * n_units)
        return self.learning_rate / n_inputs

    def learn(self, views: Sequence[FloatArray]) -> FloatArray:
        """The trained weights (H, N) after ``epochs`` passes over ``views`` (route order)."""
        patterns = np.stack(
            [self.standardized(np.asarray(v, dtype=np.float64)).ravel() for v in views]
        )
        weights = self.start_weights(patterns.shape[1])
        rate = self.step_size(weights.shape[1], weights.shape[0])
        with np.errstate(over="ignore", invalid="ignore"):  # blown-up weights: raised below
            for _ in range(self.epochs):
                for x in patterns:
                    h = weights @ x
                    weights += rate * (weights - np.outer(np.tanh(h) + h, h @ weights))
        if not np.all(np.isfinite(weights)):
            raise ValueError(
                f"infomax: the weights blew up with learning_rate {self.learning_rate}; "
                "train with a smaller one"
            )
        return weights

    def scan(self, memory: FloatArray, current: FloatArray) -> tuple[FloatArray, dict[str, Any]]:
        """Summed absolute activation (n,) of every column shift of ``current``."""
        return np.abs(rotations(self.standardized(current)) @ memory.T).sum(axis=1), {}
