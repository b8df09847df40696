"""Validation of SIFT-landmark homing (seed 001) on its paper's setting: SIFT landmarks on the
raw catadioptric image, and its headline that mismatch elimination (P) beats no elimination
(PN) where mismatches occur.

The exact case (landmarks placed by the camera model, mismatches swapped in by hand) is
tests/test_sift.py::test_elimination_removes_injected_mismatches. Here rendered raw views of a
generated room (seed 0, 5 x 5 grid, auto-exposure and sensor noise): the goal at the grid's
centre, 6 places 0.3-1.2 m away, all at the goal's heading. Mismatches are planted by swapping
the descriptors of a random 30 % of each current view's landmarks among themselves, so those
landmarks match goal landmarks at other places. Measured mean AE: P 5.1 deg, PN 11.6 deg
without planting; P 8.2 deg, PN 55 deg with it. Held: with planting P's mean below half of
PN's and below 20 deg.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import build_world
from homebench.geometry import Pose, angular_error, home_direction
from homebench.methods.base import View
from homebench.methods.sift.method import Sift, SiftFeatures

SPEC = WorldSpec(seed=0, grid={"shape": [5, 5]})
GOAL = SPEC.to_grid().position(2, 2)
HEADING = 0.4
OFFSETS = [(0.3, 0.0), (-0.6, 0.0), (0.0, 0.9), (0.0, -1.2), (0.6, -0.6), (-0.9, 0.3)]
P = Sift()
PN = Sift(horizon_constraint=False, half_plane_constraint=False)
#: Current views' features, each with its true home direction (radians, current robot frame).
Pairs = list[tuple[SiftFeatures, float]]


def _features(x: float, y: float) -> SiftFeatures:
    image = build_world(SPEC).render(Pose(x, y, HEADING), noise_seed=1)["raw"]
    return P.describe(View(image, SPEC.raw.geometry()))


def _planted(features: SiftFeatures, fraction: float, seed: int) -> SiftFeatures:
    """``features`` with the descriptors of a random ``fraction`` of them swapped round."""
    rng = np.random.default_rng(seed)
    chosen = rng.choice(len(features), int(fraction * len(features)), replace=False)
    descriptors = features.descriptors.copy()
    descriptors[chosen] = descriptors[rng.permutation(chosen)]
    return replace(features, descriptors=descriptors)


@pytest.fixture(scope="module")
def views() -> tuple[SiftFeatures, Pairs]:
    """The goal's features and the current views' :data:`Pairs`."""
    currents = [
        (_features(GOAL[0] + dx, GOAL[1] + dy), home_direction((dx, dy), (0.0, 0.0), HEADING))
        for dx, dy in OFFSETS
    ]
    return _features(*GOAL), currents


def _mean_error(method: Sift, goal: SiftFeatures, currents: Pairs) -> float:
    """Mean home-direction error (degrees) over the pairs; no estimate counts as 180 deg."""
    errors = []
    for current, truth in currents:
        angle = method.home(current, goal).angle
        errors.append(math.pi if angle is None else float(angular_error(angle, truth)))
    return math.degrees(float(np.mean(errors)))


def test_elimination_beats_no_elimination_where_mismatches_are_planted(views):
    goal, currents = views
    planted = [
        (_planted(current, 0.3, seed), truth) for seed, (current, truth) in enumerate(currents)
    ]
    p, pn = _mean_error(P, goal, planted), _mean_error(PN, goal, planted)
    assert p < 0.5 * pn and p < 20.0
