"""Recorded headings against the direction of travel: a recorder facing the way it moves (BoB's
Ant World routes, a robot driving forward) records headings equal to it, so a route's own poses
say how its headings are written.

The direction of travel at image k is that of the step from image k - 1 to image k + 1 (one
side at the ends); steps shorter than half the median step (a robot standing) are left out.
A convention (zero, sense) is fitted to travel = zero + sense x recorded heading: the sense
whose residuals are smaller, the zero their circular mean. The sense needs headings that turn
(a circular spread of at least :data:`MIN_TURN_DEG`); on a straight route only the zero is
fitted, for the stated sense.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from homebench.data.posed import PosedDatabase
from homebench.geometry import (
    Direction,
    HeadingConvention,
    angle_diff,
    circular_mean,
    other_direction,
)

FloatArray = NDArray[np.float64]

#: Headings that turn less than this (circular standard deviation, deg) tell no sense.
MIN_TURN_DEG = 15.0
#: Recorded headings follow the direction of travel when their median residual is below this.
FOLLOWS_DEG = 10.0
#: ``data show`` warns when headings and travel differ by more than this ...
WARN_DEG = 45.0
#: ... at more than this share of the route's poses.
WARN_SHARE = 0.5


def travel_directions(xy: FloatArray) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The direction of travel at each pose of ``xy`` (n, 2) metres, radians ccw from +x,
    shape (n,), and whether it is known (a step long enough), shape (n,)."""
    n = len(xy)
    if n < 2:
        return np.zeros(n), np.zeros(n, dtype=bool)
    before = np.concatenate([[0], np.arange(n - 1)])
    after = np.concatenate([np.arange(1, n), [n - 1]])
    step = xy[after] - xy[before]
    length = np.hypot(step[:, 0], step[:, 1])
    median = float(np.median(length[length > 0])) if np.any(length > 0) else 0.0
    known = length > 0.5 * median if median > 0 else np.zeros(n, dtype=bool)
    return np.arctan2(step[:, 1], step[:, 0]), known


@dataclass(frozen=True)
class TravelFit:
    """How recorded headings relate to the direction of travel: ``convention`` makes them
    equal it best (``sense_known``: the headings turn enough to tell its sense, else the
    stated sense was kept), ``median_deg`` the median residual (deg) over ``n_steps`` poses.
    ``follows``: the residuals are small, so the recorder faced the way it moved."""

    convention: HeadingConvention
    median_deg: float
    n_steps: int
    sense_known: bool

    @property
    def follows(self) -> bool:
        return self.median_deg <= FOLLOWS_DEG


def fit_travel(
    xy: FloatArray, recorded_deg: FloatArray, stated_sense: Direction
) -> TravelFit | None:
    """The convention of ``recorded_deg`` (n,) that best turns them into the direction of
    travel along ``xy`` (n, 2); None with fewer than 3 known directions of travel."""
    travel, known = travel_directions(xy)
    if known.sum() < 3:
        return None
    recorded = np.radians(recorded_deg[known])
    travel = travel[known]
    spread = math.degrees(math.sqrt(-2.0 * math.log(max(_resultant(recorded), 1e-12))))
    sense_known = spread >= MIN_TURN_DEG
    senses = (stated_sense, other_direction(stated_sense)) if sense_known else (stated_sense,)
    fits = []
    for sense in senses:
        sign = 1.0 if sense == "ccw" else -1.0
        zero = circular_mean(angle_diff(travel, sign * recorded))
        residual = np.abs(angle_diff(travel, sign * recorded + zero))
        convention = HeadingConvention(round(math.degrees(zero) % 360.0, 1), sense)
        fits.append(TravelFit(convention, math.degrees(float(np.median(residual))), len(travel),
                              sense_known))  # fmt: skip
    return min(fits, key=lambda f: f.median_deg)


def _resultant(angles: FloatArray) -> float:
    """Mean resultant length of ``angles`` (radians)."""
    return float(np.hypot(np.mean(np.cos(angles)), np.mean(np.sin(angles))))


def travel_disagreement(xy: FloatArray, world_heading_deg: FloatArray) -> tuple[float, float, int]:
    """How far the headings (deg ccw from +x, (n,)) of the poses ``xy`` (n, 2) are from the
    direction of travel: the share of poses more than :data:`WARN_DEG` off, the median
    difference (deg) and the number of poses compared (0: the route does not move)."""
    travel, known = travel_directions(xy)
    if not known.any():
        return 0.0, 0.0, 0
    off = np.degrees(np.abs(angle_diff(travel[known], np.radians(world_heading_deg[known]))))
    return float(np.mean(off > WARN_DEG)), float(np.median(off)), int(known.sum())


def route_warnings(db: PosedDatabase) -> list[str]:
    """What ``data show`` says of a route whose headings (as read) and direction of travel
    differ by more than :data:`WARN_DEG` at more than :data:`WARN_SHARE` of its poses."""
    share, median, compared = travel_disagreement(db.xy, db.heading_deg)
    if compared == 0 or share <= WARN_SHARE:
        return []
    return [
        f"the headings as read differ from the direction of travel by more than {WARN_DEG:g} "
        f"deg at {share:.0%} of the {compared} moving poses (median {median:.0f} deg): if the "
        "camera faced the way it moved, the headings are read wrong (`homebench data check` "
        "measures how they are written; headings in homebench.yaml states it)"
    ]
