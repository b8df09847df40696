"""Descriptor matching against a brute-force reference and hand-made cases."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.methods.sift.matching import match_descriptors


def _brute_force(goal, current, ratio, cross_check):
    distance = np.linalg.norm(
        goal[:, None, :].astype(np.float64) - current[None, :, :].astype(np.float64), axis=2
    )
    pairs = []
    for i, row in enumerate(distance):
        order = np.argsort(row)
        j = order[0]
        if row[j] < ratio * row[order[1]] and (not cross_check or np.argmin(distance[:, j]) == i):
            pairs.append((i, int(j)))
    return pairs


@pytest.mark.parametrize("cross_check", [False, True])
@pytest.mark.parametrize("ratio", [0.6, 0.8, 0.95])
def test_matches_equal_brute_force(ratio, cross_check):
    rng = np.random.default_rng(0)
    landmarks = rng.uniform(0, 120, (60, 128))
    goal = (landmarks[:50] + rng.normal(0, 15, (50, 128))).astype(np.float32)
    current = (landmarks[10:] + rng.normal(0, 15, (50, 128))).astype(np.float32)
    ig, ic = match_descriptors(goal, current, ratio, cross_check)
    assert list(zip(ig.tolist(), ic.tolist(), strict=True)) == _brute_force(
        goal, current, ratio, cross_check
    )
    assert ig.dtype == np.intp and ic.dtype == np.intp


def test_ambiguous_and_one_sided_matches():
    goal = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]], dtype=np.float32)
    current = np.array([[0.1, 0.0], [10.0, 1.0], [10.0, -1.0], [0.0, 9.0]], dtype=np.float32)
    # goal 1 sits between current 1 and 2 (a tie): the ratio test rejects it.
    ig, ic = match_descriptors(goal, current, 0.8, cross_check=False)
    assert ig.tolist() == [0, 2] and ic.tolist() == [0, 3]
    # goal 2 is current 3's nearest as well; current 0's nearest is goal 0: both survive.
    ig, ic = match_descriptors(goal, current, 0.8, cross_check=True)
    assert ig.tolist() == [0, 2] and ic.tolist() == [0, 3]
    # A goal descriptor that is not the current one's nearest fails the cross-check only.
    goal_extra = np.vstack([goal, [[0.0, 9.5]]]).astype(np.float32)
    ig, _ = match_descriptors(goal_extra, current, 0.8, cross_check=True)
    assert ig.tolist() == [0, 3]
    ig, _ = match_descriptors(goal_extra, current, 0.8, cross_check=False)
    assert ig.tolist() == [0, 2, 3]


def test_no_matches_without_a_second_neighbour_or_descriptors():
    one = np.ones((1, 128), np.float32)
    none = np.empty((0, 128), np.float32)
    for goal, current in ((one, one), (none, np.ones((3, 128), np.float32))):
        ig, ic = match_descriptors(goal, current, 0.8, cross_check=False)
        assert ig.size == 0 and ic.size == 0
