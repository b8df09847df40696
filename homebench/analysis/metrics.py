"""Home-vector fields and the per-pair metrics of seed 001, section 4.3: AE (eq. 11), AHC (eq. 12).

All angles are radians in the world frame (:mod:`homebench.geometry`); NaN marks a pair for
which the method gave no estimate. Such pairs are never dropped silently: every summary counts
them, and AHC says explicitly how they enter (``missing="exclude"`` or ``"orthogonal"``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:  # imported where tables are made: job workers need the per-pair metrics only
    import pandas as pd

from homebench.config import AhcDefinition
from homebench.geometry import FloatArray, Grid, angular_error, robot_to_world, world_direction

Missing = Literal["exclude", "orthogonal"]
AHC_BINS_CM = range(30, 391, 30)
BoolArray = NDArray[np.bool_]


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


def with_missing(ae: ArrayLike, missing: Missing) -> FloatArray:
    """AE (radians, any shape) with each missing estimate (NaN) kept as NaN, to be left out
    of means (``"exclude"``, the paper's reading), or counted as pi/2 (``"orthogonal"``, the
    expected error of a random guess)."""
    a = np.asarray(ae, dtype=np.float64)
    if missing == "orthogonal":
        return np.where(np.isnan(a), np.pi / 2, a)
    if missing == "exclude":
        return a
    raise ValueError(f"missing must be 'exclude' or 'orthogonal', got {missing!r}")


def _mean_ae(ae: FloatArray, missing: Missing) -> float:
    """Mean AE (radians) of a 1-D array with NaN for missing estimates, per ``missing``."""
    a = with_missing(ae, missing)
    a = a[~np.isnan(a)]
    return float(np.mean(a)) if a.size else float("nan")


def ahc(
    ae: ArrayLike, missing: Missing = "exclude", definition: AhcDefinition = "cos_mean_ae"
) -> float:
    """Average homeward component; NaN when there is no pair. ``definition``
    (:data:`AhcDefinition`): ``cos_mean_ae``, seed 001's eq. 12, the cos of the mean AE;
    ``mean_cos``, the mean of cos(AE).

    ``missing="exclude"``: the mean is over the pairs with an estimate (count the others with
    :func:`ae_summary`); ``"orthogonal"``: a missing estimate counts as AE = pi/2 (a homeward
    component of 0), the expected error of a random guess.
    """
    a = np.asarray(ae, dtype=np.float64).ravel()
    if definition == "mean_cos":
        cosines = np.cos(with_missing(a, missing))
        cosines = cosines[~np.isnan(cosines)]
        return float(np.mean(cosines)) if cosines.size else float("nan")
    return float(np.cos(_mean_ae(a, missing)))


def ahc_by_distance(
    ae: ArrayLike,
    distance_m: ArrayLike,
    bins_cm: Iterable[float] = AHC_BINS_CM,
    missing: Missing = "exclude",
    definition: AhcDefinition = "cos_mean_ae",
) -> pd.DataFrame:
    """AHC per distance bin (seed 001, Figure 9), plus a last row ``bin = "all"``.

    ``ae``, ``distance_m``: same shape, radians and metres (current to goal); the bins are
    those of :func:`distance_bins`.

    Columns: ``bin`` (centre as text, or "all"), ``centre_cm``, ``low_cm``, ``high_cm``, ``n``
    (pairs, with or without estimate), ``n_missing``, ``mean_ae_rad``, ``mean_ae_deg``, ``ahc``
    (mean and AHC as :func:`ahc` with ``missing`` and ``definition``; NaN for a bin without
    pairs).
    """
    a = np.asarray(ae, dtype=np.float64).ravel()
    if a.size != np.size(distance_m):
        raise ValueError(f"ae has {a.size} pairs, distance_m {np.size(distance_m)}")
    import pandas as pd

    bins, masks = distance_bins(distance_m, bins_cm)
    stats = pd.DataFrame([_bin_stats(a[mask], missing, definition) for mask in masks])
    return pd.concat([bins, stats], axis=1)


def distance_bins(
    distance_m: ArrayLike, bins_cm: Iterable[float] = AHC_BINS_CM
) -> tuple[pd.DataFrame, BoolArray]:
    """The distance bins of the AHC and which pairs fall in each, plus a last bin "all".

    ``distance_m``: shape (n_pairs,) (or any, flattened), metres. ``bins_cm``: at least two
    increasing bin centres in cm. A pair belongs to the bin whose centre is nearest: bin k spans
    ``[low, high)`` with edges halfway between neighbouring centres, and half the neighbouring
    step beyond the first and last centre. Distances on a grid of the bins' step (0.3 * k m for
    30 cm bins) lie at centres, far from any edge, so floating-point error cannot move them.
    Pairs outside every bin (distance 0, beyond the last edge) are only in "all", which holds
    every pair given.

    Returns the bins (columns ``bin``: centre as text or "all", ``centre_cm``, ``low_cm``,
    ``high_cm``; NaN for "all") and the masks, shape (n_bins + 1, n_pairs), in the same order.
    """
    import pandas as pd

    d_cm = 100.0 * np.asarray(distance_m, dtype=np.float64).ravel()
    centres = np.asarray(list(bins_cm), dtype=np.float64)
    if centres.size < 2 or np.any(np.diff(centres) <= 0):
        raise ValueError("bins_cm must be at least two increasing bin centres")
    mids = (centres[:-1] + centres[1:]) / 2
    lows = np.concatenate([[1.5 * centres[0] - 0.5 * centres[1]], mids])
    highs = np.concatenate([mids, [1.5 * centres[-1] - 0.5 * centres[-2]]])
    bins = pd.DataFrame(
        {
            "bin": [f"{c:g}" for c in centres] + ["all"],
            "centre_cm": np.append(centres, np.nan),
            "low_cm": np.append(lows, np.nan),
            "high_cm": np.append(highs, np.nan),
        }
    )
    inside = (d_cm >= lows[:, None]) & (d_cm < highs[:, None])
    return bins, np.vstack([inside, np.ones((1, d_cm.size), dtype=bool)])


def _bin_stats(
    ae: FloatArray, missing: Missing, definition: AhcDefinition
) -> dict[str, float | int]:
    """The statistics of one bin of :func:`ahc_by_distance` for its AE values (1-D, NaN =
    missing)."""
    mean = _mean_ae(ae, missing)
    return {
        "n": int(ae.size),
        "n_missing": int(np.sum(np.isnan(ae))),
        "mean_ae_rad": mean,
        "mean_ae_deg": float(np.degrees(mean)),
        "ahc": ahc(ae, missing, definition),
    }
