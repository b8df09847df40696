"""Home-vector fields and the per-pair metrics of seed 001, section 4.3: AE (eq. 11), AHC (eq. 12).

All angles are radians in the world frame (:mod:`homebench.geometry`); NaN marks a pair for
which the method gave no estimate. Such pairs are never dropped silently: every summary counts
them, and AHC says explicitly how they enter (``missing="exclude"`` or ``"orthogonal"``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from homebench.geometry import FloatArray, Grid, angular_error, robot_to_world, world_direction

Missing = Literal["exclude", "orthogonal"]
AHC_BINS_CM = range(30, 391, 30)


@dataclass(frozen=True, eq=False)
class HomeField:
    """The estimated home directions towards one goal at every position of a grid.

    ``angles``: shape ``grid.shape`` = (nx, ny), world-frame direction in radians at grid index
    (i, j), NaN where the method gave no estimate. The entry at the goal itself is never used
    (the home direction at the goal is undefined; any value will do).
    """

    grid: Grid
    goal: tuple[int, int]
    angles: FloatArray

    def __post_init__(self) -> None:
        angles = np.array(self.angles, dtype=np.float64)
        if angles.shape != self.grid.shape:
            raise ValueError(f"angles have shape {angles.shape}, the grid {self.grid.shape}")
        goal = (int(self.goal[0]), int(self.goal[1]))
        if not self.grid.contains(*goal):
            raise ValueError(f"goal {goal} lies outside the grid of shape {self.grid.shape}")
        angles.setflags(write=False)
        object.__setattr__(self, "angles", angles)
        object.__setattr__(self, "goal", goal)

    @classmethod
    def from_robot_frame(
        cls, grid: Grid, goal: tuple[int, int], azimuths: ArrayLike, headings: ArrayLike
    ) -> HomeField:
        """Field from robot-frame estimates ``azimuths`` (nx, ny; NaN = none) and the headings
        of the current images (a scalar or shape (nx, ny)), both radians."""
        return cls(grid, goal, robot_to_world(azimuths, headings))

    @classmethod
    def ideal(cls, grid: Grid, goal: tuple[int, int]) -> HomeField:
        """The true field: at each position the direction to the goal (0 at the goal itself)."""
        xy = grid.position(*np.indices(grid.shape))
        return cls(grid, goal, world_direction(xy, grid.position(*goal)))

    @property
    def goal_xy(self) -> FloatArray:
        """World position (x, y) of the goal in metres, shape (2,)."""
        return self.grid.position(*self.goal)


def angular_errors(
    estimate_world: ArrayLike, current_xy: ArrayLike, goal_xy: ArrayLike
) -> FloatArray:
    """AE per pair (eq. 11): ``|wrap(estimate - atan2(yH - yC, xH - xC))|`` in [0, pi].

    ``estimate_world``: shape (...), world-frame radians, NaN where there is no estimate (the
    AE is NaN there too). ``current_xy``, ``goal_xy``: shape (..., 2), metres. A pair whose
    current position is its goal has no true direction: it raises ValueError; leave such pairs
    out.
    """
    current = np.asarray(current_xy, dtype=np.float64)
    goal = np.asarray(goal_xy, dtype=np.float64)
    coincident = np.all(current == goal, axis=-1)
    if np.any(coincident):
        raise ValueError(
            f"{int(np.sum(coincident))} pair(s) have the current position at the goal: "
            "the true home direction is undefined"
        )
    return angular_error(estimate_world, world_direction(current, goal))


def ae_summary(ae: ArrayLike) -> dict[str, float | int]:
    """Mean and median AE over the pairs with an estimate, and the pairs without one.

    ``ae``: any shape, radians, NaN = no estimate. Keys: ``n`` (all pairs), ``n_missing``,
    ``missing_share``, ``mean_rad``, ``median_rad``, ``mean_deg``, ``median_deg`` (NaN when no
    pair has an estimate).
    """
    a = np.asarray(ae, dtype=np.float64).ravel()
    valid = a[~np.isnan(a)]
    n, n_missing = a.size, a.size - valid.size
    mean = float(np.mean(valid)) if valid.size else float("nan")
    median = float(np.median(valid)) if valid.size else float("nan")
    return {
        "n": n,
        "n_missing": n_missing,
        "missing_share": n_missing / n if n else float("nan"),
        "mean_rad": mean,
        "median_rad": median,
        "mean_deg": float(np.degrees(mean)),
        "median_deg": float(np.degrees(median)),
    }


def _mean_ae(ae: FloatArray, missing: Missing) -> float:
    """Mean AE (radians) of a 1-D array with NaN for missing estimates, per ``missing``."""
    if missing == "orthogonal":
        ae = np.where(np.isnan(ae), np.pi / 2, ae)
    elif missing == "exclude":
        ae = ae[~np.isnan(ae)]
    else:
        raise ValueError(f"missing must be 'exclude' or 'orthogonal', got {missing!r}")
    return float(np.mean(ae)) if ae.size else float("nan")


def ahc(ae: ArrayLike, missing: Missing = "exclude") -> float:
    """Average homeward component (eq. 12): cos of the mean AE; NaN when there is no pair.

    ``missing="exclude"``: the mean is over the pairs with an estimate (count the others with
    :func:`ae_summary`); ``"orthogonal"``: a missing estimate counts as AE = pi/2, the expected
    error of a random guess.
    """
    return float(np.cos(_mean_ae(np.asarray(ae, dtype=np.float64).ravel(), missing)))


def ahc_by_distance(
    ae: ArrayLike,
    distance_m: ArrayLike,
    bins_cm: Iterable[float] = AHC_BINS_CM,
    missing: Missing = "exclude",
) -> pd.DataFrame:
    """AHC per distance bin (seed 001, Figure 9), plus a last row ``bin = "all"``.

    ``ae``, ``distance_m``: same shape, radians and metres (current to goal). ``bins_cm``: at
    least two increasing bin centres in cm. A pair belongs to the bin whose centre is nearest: bin k
    spans ``[low, high)`` with edges halfway between neighbouring centres, and half the
    neighbouring step beyond the first and last centre. Distances on a grid of the bins' step
    (0.3 * k m for 30 cm bins) lie at centres, far from any edge, so floating-point error cannot
    move them. Pairs outside every bin (distance 0, beyond the last edge) count only in the
    ``"all"`` row, which covers every pair given.

    Columns: ``bin`` (centre as text, or "all"), ``centre_cm``, ``low_cm``, ``high_cm``, ``n``
    (pairs, with or without estimate), ``n_missing``, ``mean_ae_rad``, ``mean_ae_deg``, ``ahc``
    (mean and AHC as :func:`ahc` with ``missing``; NaN for a bin without pairs).
    """
    a = np.asarray(ae, dtype=np.float64).ravel()
    d_cm = 100.0 * np.asarray(distance_m, dtype=np.float64).ravel()
    if a.shape != d_cm.shape:
        raise ValueError(f"ae has {a.size} pairs, distance_m {d_cm.size}")
    centres = np.asarray(list(bins_cm), dtype=np.float64)
    if centres.size < 2 or np.any(np.diff(centres) <= 0):
        raise ValueError("bins_cm must be at least two increasing bin centres")
    mids = (centres[:-1] + centres[1:]) / 2
    lows = np.concatenate([[1.5 * centres[0] - 0.5 * centres[1]], mids])
    highs = np.concatenate([mids, [1.5 * centres[-1] - 0.5 * centres[-2]]])

    rows = [
        _bin_row(f"{c:g}", c, lo, hi, a[(d_cm >= lo) & (d_cm < hi)], missing)
        for c, lo, hi in zip(centres, lows, highs, strict=True)
    ]
    rows.append(_bin_row("all", np.nan, np.nan, np.nan, a, missing))
    return pd.DataFrame(rows)


def _bin_row(
    label: str, centre: float, low: float, high: float, ae: FloatArray, missing: Missing
) -> dict[str, str | float | int]:
    """One row of :func:`ahc_by_distance` for the AE values ``ae`` (1-D, NaN = missing)."""
    mean = _mean_ae(ae, missing)
    return {
        "bin": label,
        "centre_cm": float(centre),
        "low_cm": float(low),
        "high_cm": float(high),
        "n": int(ae.size),
        "n_missing": int(np.sum(np.isnan(ae))),
        "mean_ae_rad": mean,
        "mean_ae_deg": float(np.degrees(mean)),
        "ahc": float(np.cos(mean)),
    }
