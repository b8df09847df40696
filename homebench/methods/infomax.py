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
the smallest (protocol and conventions: :mod:`homebench.methods.familiarity`).

What was verified against public sources and what is a reading: the rule above, the
familiarity ``sum |h|``, as many novelty units as pixels, one presentation per view and pixels
scaled to [0, 1] agree with the authors' group's public code (``infomax_train.m``, the BoB
robotics library's ``InfoMax``); the paper's own text was out of reach here. The learning rate,
the initial weights and the view size are readings (see the parameters). Weights that grow
without bound (a learning rate too large for the views) raise a ValueError naming the rate.

Validation (tests/test_validation_route_memory.py), on the scene of
:mod:`~homebench.methods.perfect_memory`'s validation, at the defaults: median heading error
1.0-2.4 deg at every distance up to 1 m from the route, 71-86 % of probes within 45 deg
(perfect memory: 86-93 %), catchment the 1 m tested.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from homebench.errors import ConfigError
from homebench.methods.base import ImageKind
from homebench.methods.familiarity import FloatArray, RouteMemory, rotations
from homebench.methods.params import documented, param
from homebench.methods.registry import register
from homebench.methods.warping import is_flat


@register
@documented
@dataclass(frozen=True)
class Infomax(RouteMemory):
    """Infomax (Baddeley et al. 2012): a network trained on the route's views by the Infomax
    rule; the heading is the rotation with the smallest summed absolute activation."""

    name: ClassVar[str] = "infomax"
    image_kind: ClassVar[ImageKind] = "unfolded"

    learning_rate: float = param(
        0.01,
        "eta of the Infomax rule (the update is scaled by eta / N, N the number of pixels).",
        reading="0.01 is the value recalled for the paper but not verified from its text "
        "here; the authors' group's public code trains with 0.001 and lowers it when the "
        "weights blow up (infomax_train.m), the BoB robotics library defaults to 0.0001",
    )
    epochs: int = param(
        1,
        "Presentations of the whole training route (route order each time).",
        reading="one pass, each view presented once, as the authors' code trains",
    )
    hidden_units: int | None = param(
        None,
        "Novelty units H; None: as many as the view has pixels.",
        reading="as many units as pixels, as the authors' code comments say is normal",
    )
    standardize: bool = param(
        False,
        "Give the network each view at zero mean and unit standard deviation (its grey levels "
        "shifted and scaled); use with a smaller learning_rate (0.001).",
        paper="the network takes the pixels as grey levels in [0, 1], as the authors' code "
        "does. How much a view changes the weights grows with its contrast, so the learning "
        "rate suits one kind of scene: the generated rooms' views (grey-level SD about 0.05 "
        "at 90 x 17) learn little at 0.001, and at 0.01 a one-view memory is no compass "
        "(posters room: median rotation error 114 deg, route headings within 8 deg up to "
        "0.5 m off the route); standardized views at 0.001 follow as perfect memory does "
        "and find the rotation (0.7 deg)",
    )
    seed: int = param(
        0,
        "Seed of the initial weights: uniform in [-0.5, 0.5], then each unit's weights shifted "
        "and scaled to mean 0 and standard deviation 1.",
        reading="the paper's initialisation could not be checked here; the BoB robotics "
        "library draws normal weights and normalises each unit's the same way",
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.learning_rate <= 0 or self.epochs < 1:
            raise ConfigError("infomax: learning_rate must be positive and epochs at least 1")
        if self.hidden_units is not None and self.hidden_units < 1:
            raise ConfigError("infomax: hidden_units must be at least 1 or null")

    def standardized(self, view: FloatArray) -> FloatArray:
        """The view (rows, columns) as the network takes it: as described, or with
        ``standardize`` at zero mean and unit standard deviation (a flat view: zeros)."""
        if not self.standardize:
            return view
        return np.zeros_like(view) if is_flat(view) else (view - np.mean(view)) / np.std(view)

    def start_weights(self, n_inputs: int) -> FloatArray:
        """Initial weights (H, n_inputs): seeded uniform, per unit mean 0 and SD 1."""
        units = self.hidden_units or n_inputs
        rng = np.random.default_rng(self.seed)
        weights = rng.uniform(-0.5, 0.5, (units, n_inputs))
        weights -= weights.mean(axis=1, keepdims=True)
        return weights / weights.std(axis=1, keepdims=True)

    def learn(self, views: Sequence[FloatArray]) -> FloatArray:
        """The trained weights (H, N) after ``epochs`` passes over ``views`` (route order)."""
        patterns = np.stack(
            [self.standardized(np.asarray(v, dtype=np.float64)).ravel() for v in views]
        )
        weights = self.start_weights(patterns.shape[1])
        rate = self.learning_rate / patterns.shape[1]
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
