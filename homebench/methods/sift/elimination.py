"""Seed 001, section 3.2: mismatch elimination by two distribution constraints.

**Constraint 1** (eq. 8): a landmark and its match lie on the same side of the horizon circle
(``gamma_IO``, from :meth:`CatadioptricGeometry.horizon_side`; both within its tolerance band
counts as "on" it), or the pair is discarded.

**Constraint 2** (eq. 9-10): for a tested pair (L_T, L~_T), the ``n_references`` landmarks
nearest to L_T in the goal image (among the other surviving pairs) are the references; a
reference votes for the pair when it lies on the same side of the directed line O -> L_T in the
goal image as its match does of O -> L~_T in the current image. The pair is kept when its votes
reach ``vote_threshold``. A pair with fewer references than that (fewer surviving pairs) cannot
be confirmed and is discarded, as the paper's rule reads.

Eq. 9 in bearings: with O the mirror's centre, ``D_R = (y_T - y_O)(x_R - x_O) - (x_T - x_O)(y_R
- y_O) = -|OT| |OR| sin(angle_R - angle_T)`` for image angles, and a camera's image angle is
``zero_angle +- azimuth`` with the same sign in both images. So ``gamma_LR`` agrees between the
images exactly when ``sign(sin(azimuth_R - azimuth_T))`` does; the test is done on azimuths,
which also makes it apply to unfolded panoramas (the half-planes become the two sides of the
vertical plane through the tested landmark's ray).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


def horizon_constraint(side_goal: NDArray[np.int8], side_current: NDArray[np.int8]) -> BoolArray:
    """Constraint 1: True where ``gamma_IO`` of the goal landmark equals its match's; shape (m,)."""
    return np.asarray(side_goal) == np.asarray(side_current)


def reference_landmarks(
    positions: FloatArray, n_references: int, period: float
) -> NDArray[np.intp]:
    """Indices (m, k) of each landmark's k = min(n_references, m - 1) nearest other landmarks,
    nearest first.

    ``positions``: goal-image pixels (u, v), shape (m, 2). ``period`` > 0 wraps the u distance
    (an unfolded panorama's width); 0 for a raw image.
    """
    m = len(positions)
    k = min(n_references, m - 1)
    if k < 1:
        return np.empty((m, 0), dtype=np.intp)
    p = np.asarray(positions, dtype=np.float32)
    du = np.abs(p[:, None, 0] - p[None, :, 0])
    if period > 0:
        du = np.minimum(du, period - du)
    distance = du**2 + (p[:, None, 1] - p[None, :, 1]) ** 2
    np.fill_diagonal(distance, np.inf)
    # k rounds of a row-wise argmin (k is small): several times faster than argpartition.
    rows = np.arange(m)
    nearest = np.empty((m, k), dtype=np.intp)
    for column in range(k):
        nearest[:, column] = np.argmin(distance, axis=1)
        distance[rows, nearest[:, column]] = np.inf
    return nearest


def half_plane_votes(
    positions_goal: FloatArray,
    azimuths_goal: FloatArray,
    azimuths_current: FloatArray,
    n_references: int,
    period: float,
) -> NDArray[np.intp]:
    """Constraint 2's votes V_m of each matched pair, shape (m,).

    ``positions_goal``: the goal landmarks' pixels (m, 2) (for the nearest references);
    ``azimuths_goal``, ``azimuths_current``: the pair's azimuths (m,), radians.
    """
    refs = reference_landmarks(positions_goal, n_references, period)
    goal = np.asarray(azimuths_goal, dtype=np.float64)
    current = np.asarray(azimuths_current, dtype=np.float64)
    side_goal = np.sign(np.sin(goal[refs] - goal[:, None]))
    side_current = np.sign(np.sin(current[refs] - current[:, None]))
    return np.sum(side_goal == side_current, axis=1).astype(np.intp)


def half_plane_constraint(
    positions_goal: FloatArray,
    azimuths_goal: FloatArray,
    azimuths_current: FloatArray,
    n_references: int,
    vote_threshold: int,
    period: float,
) -> BoolArray:
    """Constraint 2: True for the pairs whose votes reach ``vote_threshold``; shape (m,)."""
    votes = half_plane_votes(positions_goal, azimuths_goal, azimuths_current, n_references, period)
    return votes >= vote_threshold
