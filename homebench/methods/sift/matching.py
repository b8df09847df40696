"""Descriptor matching: exact nearest neighbours, Lowe's ratio test, optional cross-check.

Exact L2 distances by one matrix product (BLAS) instead of ``cv2.BFMatcher``: the same
neighbours, no per-match Python objects, and one matrix serves the cross-check as well.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

IndexArray = NDArray[np.intp]


def match_descriptors(
    goal: NDArray[np.float32],
    current: NDArray[np.float32],
    ratio: float,
    cross_check: bool,
) -> tuple[IndexArray, IndexArray]:
    """Matches of goal descriptors (n, d) to current descriptors (m, d).

    Each goal descriptor takes its nearest current one when that is nearer than ``ratio`` times
    the second nearest (Lowe 2004); with ``cross_check`` the goal descriptor must also be the
    current one's nearest. Needs m >= 2 (no ratio without a second neighbour). Returns index
    arrays ``(goal_index, current_index)``, shape (k,) each, in increasing goal index.
    """
    if len(goal) == 0 or len(current) < 2:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    # Squared distance = |g|^2 + partial; |g|^2 is constant along a row, so partial ranks each
    # goal descriptor's neighbours, and |g|^2 is added only to the two distances the ratio needs.
    partial = (-2.0 * goal) @ current.T
    partial += np.einsum("ij,ij->i", current, current)[None, :]
    goal_sq = np.einsum("ij,ij->i", goal, goal)
    rows = np.arange(len(goal))
    nearest = np.argmin(partial, axis=1)
    if cross_check:
        mutual = np.argmin(partial + goal_sq[:, None], axis=0)[nearest] == rows
    first = np.maximum(partial[rows, nearest] + goal_sq, 0.0)
    partial[rows, nearest] = np.inf
    second = np.maximum(np.min(partial, axis=1) + goal_sq, 0.0)
    keep = first < ratio**2 * second
    if cross_check:
        keep &= mutual
    return rows[keep].astype(np.intp), nearest[keep].astype(np.intp)
