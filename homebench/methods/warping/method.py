"""Franz et al. (1998) 1-D warping on the horizon signal.

Model (seed 001, section 2, eq. 1-4): the robot left the goal H in direction ``alpha`` (goal
robot frame) for a distance ``d`` and turned by ``psi`` (ccw, goal heading -> current heading);
all landmarks lie at one distance ``r`` from H, ``rho = d / r``. A landmark seen at azimuth
``theta`` from H is seen at ``theta'`` from the current place C with
``sin(psi + theta' - theta) = rho * sin(psi + theta' - alpha)`` (eq. 2). Solved for ``theta``
(the branch on the ray's forward side, valid for rho < 1):
``theta = phi - arcsin(rho * sin(phi - alpha))`` with ``phi = theta' + psi``. So the goal signal
warped by (rho, alpha) and rotated by psi predicts the current signal; the search minimises their
distance and the home direction is ``beta = alpha - psi + pi`` (eq. 4), in the
current robot frame.

Speed (:mod:`homebench.methods.warping.search`): alpha and psi are whole column shifts, so all
hypotheses are one float32 matrix product of the current signal's shifts with the goal warped
for every (rho, alpha), built by copying rows; the best few are re-scored exactly in float64
(:meth:`Warping.costs`, hypothesis by hypothesis), so the optimum does not depend on the BLAS
kernel or thread count. The goal's part is kept for the last few goals (a job homes every
current view to one goal).

Readings and options (see the parameters): the 1-D signal is the mean of a band of rows around
the horizon, one column per psi step; seed 001 does not say how W compares images, homebench
reads the sum of squared differences (``distance``); no normalisation of the signal
(``normalize``, an option). ``rho = 0`` (no displacement found) carries no direction: the warp
is then the identity for every alpha, which all tie exactly (the search reports alpha = 0), so
eq. 4 would turn the search order into a direction; the estimate has ``angle=None`` (counted as
"no estimate") but keeps the rotation.
A texture-less signal gives :meth:`HomingEstimate.none`.

Validation (tests/test_validation_warping.py), on the paper's scene, every landmark at one
distance from the goal: ray-traced 1-D signals of a landmark ring, displaced and turned on
Table 1's grid, give rho, alpha and psi exactly and the home direction to 1e-9 rad; rendered
panoramas with the goal at the centre of a round arena (wall 3 m away all round), 24 places
0.3-1.5 m away (rho 0.1-0.5), each view also turned by -37.5 deg, give a mean AE of 2.5 deg
(AHC 0.999), at most 13 deg (0.3 m away, small parallax against the 5 deg steps), and the
turn within half a psi step.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, wrap_angle
from homebench.imaging.horizon import horizon_signal
from homebench.methods.base import HomingEstimate, ImageKind, View, is_flat
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register
from homebench.methods.warping.search import (
    Best,
    GoalScreen,
    SearchGrid,
    all_costs,
    screen_goal,
    search_grid,
    search_many,
)
from homebench.methods.warping.search import warp_tables as warp_tables  # shared by warping-2d

FloatArray = NDArray[np.float64]
#: Goals whose part of the search screen one method instance keeps.
SCREEN_CACHE_SIZE = 4

Normalize = Literal["none", "equalize", "zscore"]
SignalDistance = Literal["ssd", "dot"]


def normalize_signal(signal: FloatArray, mode: Normalize) -> FloatArray:
    """``signal`` (n,) as the method compares it: unchanged (``none``), histogram-equalised
    (``equalize``: each value's rank, the fraction of values <= it, times 255; unchanged by any
    increasing grey-level mapping), or zero mean and unit standard deviation (``zscore``:
    unchanged by any gain and offset; a flat signal gives zeros)."""
    if mode == "equalize":
        ranks = np.searchsorted(np.sort(signal), signal, side="right")
        return 255.0 * ranks / signal.size
    if mode == "zscore":
        centred = signal - signal.mean()
        spread = centred.std()
        return centred / spread if spread > 0 else np.zeros_like(centred)
    return signal


@register
@documented
@dataclass(frozen=True)
class Warping:
    """1-D warping; defaults: seed 001 Table 1 (rho in [0, 0.95] in 20 steps, alpha/psi 5 deg)."""

    name: ClassVar[str] = "warping"
    image_kind: ClassVar[ImageKind] = "unfolded"

    n_rho: int = param(20, "Search steps of rho = d / r from 0 to rho_max (Table 1).")
    rho_max: float = param(0.95, "Largest rho searched (Table 1).")
    n_alpha: int = param(72, "Search steps of alpha over a full turn (Table 1: 5 deg).")
    n_psi: int = param(72, "Search steps of psi over a full turn (Table 1: 5 deg).")
    n_columns: int = param(
        72,
        "Columns of the 1-D horizon signal (a multiple of n_alpha and of n_psi).",
        reading="not stated; one column per psi step, which on a 288-column panorama averages "
        "four columns (a low-pass before warping)",
    )
    band_half_width_deg: float = param(
        5.0,
        "The signal is the mean of the rows within this many degrees of the horizon.",
        reading="not stated; enough rows to average out noise and a slight tilt, few enough to "
        "stay at camera height where the equal-distance model holds best",
    )
    normalize: Normalize = param(
        "none",
        "Grey-level normalisation of each signal before comparing: none, equalize (rank "
        "histogram equalisation) or zscore (zero mean, unit deviation).",
        paper="describes no normalisation: grey levels as they are, so a global brightness "
        "change between the views shifts every distance (seed 001: W collapses under day)",
    )
    distance: SignalDistance = param(
        "ssd",
        "How the warped goal signal is compared with the current one: ssd (sum of squared "
        "differences, minimised) or dot (scalar product, maximised).",
        reading="seed 001 does not say; the sum of squared differences of the warping baselines "
        "on the Bielefeld databases (Möller's and Vardy's implementations); dot is the scalar "
        "product Möller's early reimplementation of Franz et al. (1998) used by default",
    )

    # The goal's part of the search screen, by the goal signal's bytes: the currents of one
    # goal share it. Not a parameter.
    _screens: dict[bytes, GoalScreen | None] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        check_fields(self)
        if self.n_rho < 2 or not 0.0 < self.rho_max < 1.0:
            raise ConfigError("warping: need n_rho >= 2 and 0 < rho_max < 1")
        if self.n_alpha < 1 or self.n_psi < 1 or self.n_columns % self.n_psi:
            raise ConfigError("warping: n_columns must be a multiple of n_psi (psi = whole shifts)")
        if self.n_columns % self.n_alpha:
            raise ConfigError("warping: n_columns must be a multiple of n_alpha (whole shifts)")
        if not 0.0 < self.band_half_width_deg < 90.0:
            raise ConfigError("warping: band_half_width_deg must be in (0, 90)")

    @property
    def rho(self) -> tuple[float, ...]:
        """Searched rho values: 0 .. rho_max in n_rho steps."""
        return rho_grid(self.rho_max, self.n_rho)

    def describe(self, view: View) -> FloatArray:
        """The 1-D horizon signal (n_columns,), canonical column order, normalised (grey levels
        for ``normalize="none"``)."""
        signal = horizon_signal(
            view.image, view.geometry, np.radians(self.band_half_width_deg), self.n_columns
        )
        return normalize_signal(signal, self.normalize)

    def costs(self, current: FloatArray, goal: FloatArray) -> FloatArray:
        """Distance of every (rho, alpha, psi), lower is better: shape (n_rho, n_alpha, n_psi),
        float64, hypothesis by hypothesis (the reference :meth:`home` finds the argmin of).

        ``ssd``: sum of squared differences; ``dot``: minus the scalar product."""
        return all_costs(self._grid, current, goal, self.distance == "ssd")

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (rho, alpha, psi): the argmin of
        :meth:`costs`, found by a float32 screen and exact float64 re-scoring (see
        :mod:`homebench.methods.warping.search`)."""
        return self.home_many([current], goal)[0]

    def home_many(self, currents: Sequence[FloatArray], goal: FloatArray) -> list[HomingEstimate]:
        """:meth:`home` of each current signal (n_columns,) towards one goal, bit for bit: the
        screens of a few currents at a time are one matrix product
        (:func:`~homebench.methods.warping.search.search_many`)."""
        if any(f.shape != (self.n_columns,) for f in (goal, *currents)):
            raise ValueError(f"warping: features must have shape ({self.n_columns},)")
        screen = self._screen(goal)
        textured = [] if screen is None else [k for k, c in enumerate(currents) if not is_flat(c)]
        found: dict[int, Best] = {}
        if screen is not None and textured:
            signals = np.array([currents[k] for k in textured], dtype=np.float64)  # (K, n)
            best = search_many(self._grid, signals, goal, screen, self.distance == "ssd")
            found = dict(zip(textured, best, strict=True))
        shape = (self.n_rho, self.n_alpha, self.n_psi)
        return [
            estimate_at(*found[k], shape, self.rho, self.n_columns)
            if k in found
            else HomingEstimate.none(n_landmarks=self.n_columns, reason="no texture")
            for k in range(len(currents))
        ]

    @cached_property
    def _grid(self) -> SearchGrid:
        return search_grid(self.n_columns, self.rho, self.n_alpha, self.n_psi)

    def _screen(self, goal: FloatArray) -> GoalScreen | None:
        """The goal's part of the screen (None: the goal has no texture), kept for the last
        goals (a job homes every current view to one goal)."""
        key = goal.tobytes()
        if key not in self._screens:
            if len(self._screens) >= SCREEN_CACHE_SIZE:
                self._screens.clear()
            flat = is_flat(goal)
            ssd = self.distance == "ssd"
            self._screens[key] = None if flat else screen_goal(self._grid, goal, ssd)
        return self._screens[key]


@lru_cache(maxsize=64)
def rho_grid(rho_max: float, n_rho: int) -> tuple[float, ...]:
    """The rho values a warping search tries: ``n_rho`` evenly from 0 to ``rho_max``."""
    return tuple(np.linspace(0.0, rho_max, n_rho).tolist())


def best_hypothesis(cost: FloatArray, rho: tuple[float, ...], n_landmarks: int) -> HomingEstimate:
    """The estimate of a warping search's best (rho, alpha, psi), the first minimum of ``cost``
    (shape (n_rho, n_alpha, n_psi), lower is better): see :func:`estimate_at`. Shared by every
    warping variant."""
    index = np.unravel_index(int(np.argmin(cost)), cost.shape)
    r, a, p = (int(i) for i in index)
    return estimate_at((r, a, p), float(cost[r, a, p]), cost.shape, rho, n_landmarks)


def estimate_at(
    index: tuple[int, int, int],
    score: float,
    shape: tuple[int, ...],
    rho: tuple[float, ...],
    n_landmarks: int,
) -> HomingEstimate:
    """The estimate of hypothesis ``index = (r, a, p)`` of a search grid of ``shape`` (n_rho,
    n_alpha, n_psi; alpha and psi evenly spaced over a full turn): home direction eq. 4,
    ``beta = alpha - psi + pi``, rotation psi, ``score`` its cost. ``rho``: the searched
    values (n_rho,), the first 0 (no displacement: no direction, see the module docstring).
    """
    r, a, p = index
    alpha = TWO_PI * a / shape[1]
    psi = float(wrap_angle(TWO_PI * p / shape[2]))
    return HomingEstimate(
        angle=None if r == 0 else float(wrap_angle(alpha - psi + np.pi)),
        rotation=psi,
        n_landmarks=n_landmarks,
        score=score,
        diagnostics={"rho": rho[r], "alpha": float(alpha), "psi": psi},
    )
