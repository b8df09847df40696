"""The pieces of visual route homing on the analytic arena: patch similarity, the pose
correction's re-finding, the anchor, and the sector law on logged goal positions.

Ground truth: pure turns are whole-column rolls of a panorama (exact), and the arena's home
direction is known for any pose.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import GEOMETRY, render

from homebench.experiments.route.visual import (
    VisualHomingParams,
    anchor,
    leg_motion,
    patch_similarity,
    refind,
)
from homebench.geometry import Pose, angular_error, home_direction
from homebench.methods.klt_sector.tracking import KltTracker, Tracks

TRACKER = KltTracker()
GOAL = Pose(0.3, -0.2, 0.5)


@pytest.fixture(scope="module")
def goal() -> tuple[np.ndarray, Tracks]:
    image = render(GOAL).image
    return image, Tracks.start(TRACKER.detect(image))


def test_patch_similarity_is_one_for_the_same_patch_even_across_column_zero(goal) -> None:
    image, tracks = goal
    shift = 7  # a roll by whole columns moves every patch, some across the seam
    moved = tracks.positions.copy()
    moved[:, 0] = (moved[:, 0] + shift) % GEOMETRY.width
    same = patch_similarity(image, tracks.positions, np.roll(image, shift, axis=1), moved, 21)
    assert np.all(same > 0.999)
    moved[:, 1] = np.clip(moved[:, 1] + 15, 0, GEOMETRY.height - 1)  # other patches
    assert np.median(patch_similarity(image, tracks.positions, image, moved, 21)) < 0.9
    flat = np.full_like(image, 128)
    assert np.all(patch_similarity(image, tracks.positions, flat, tracks.positions, 21) == 0)


def test_refind_after_a_turn_on_the_spot(goal) -> None:
    image, tracks = goal
    turn = math.radians(100.0)  # a 100 deg ccw turn is a roll by -80 columns
    turned = render(Pose(GOAL.x, GOAL.y, GOAL.heading + turn)).image
    found = refind(TRACKER, image, tracks.ids, tracks.positions, turned, turn, GEOMETRY)
    assert len(found) >= 0.95 * len(tracks)
    expected = tracks.positions[np.searchsorted(tracks.ids, found.ids)]
    shift = (found.positions[:, 0] - expected[:, 0]) % GEOMETRY.width
    assert np.allclose(shift, GEOMETRY.width - 80, atol=0.05)
    assert np.allclose(found.positions[:, 1], expected[:, 1], atol=0.05)


def test_anchor_takes_good_direct_matches_and_keeps_the_rest(goal) -> None:
    image, tracks = goal
    drifted = Tracks(tracks.ids, tracks.positions + np.float32([0.6, -0.4]), tracks.alive, 0)
    fixed = anchor(TRACKER, image, tracks, drifted, image, 0.9)  # at the goal itself
    assert np.allclose(fixed.positions, tracks.positions, atol=0.05)
    flat = np.full_like(image, 128)  # nothing to match: every drifted position stays
    kept = anchor(TRACKER, image, tracks, drifted, flat, 0.9)
    assert np.array_equal(kept.positions, drifted.positions)


@pytest.mark.parametrize("offset", [(0.3, 0.0), (0.0, -0.4), (-0.25, 0.25)])
def test_leg_motion_points_home_and_vanishes_at_the_goal(goal, offset) -> None:
    image, tracks = goal
    params = VisualHomingParams()
    row = {i: k for k, i in enumerate(tracks.ids.tolist())}
    at_goal, kept, phi = leg_motion(tracks, tracks.positions, row, GEOMETRY, params)
    assert at_goal is not None and np.hypot(*at_goal) < 1e-9 and phi == pytest.approx(0.0)
    here = Pose(GOAL.x + offset[0], GOAL.y + offset[1], GOAL.heading - 0.3)
    view = render(here).image
    found = refind(TRACKER, image, tracks.ids, tracks.positions, view, -0.3, GEOMETRY)
    motion, kept, phi = leg_motion(found, tracks.positions, row, GEOMETRY, params)
    assert kept >= 20 and phi == pytest.approx(-0.3, abs=0.05)
    truth = home_direction(here.xy, GOAL.xy, here.heading)
    assert angular_error(math.atan2(motion[1], motion[0]), truth) < math.radians(30.0)
