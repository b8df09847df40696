"""Average landmark vector: symmetric scenes, rotation, degenerate inputs, the arena.

Arena tolerance: the arena's grey wall texture (not the papers' black and white) thresholded
by Otsu's rule gives five dark sectors; a sector that splits, merges or vanishes between the
views moves the ALV by about 1/5, while the lattice displacements (0.3-0.85 m in a 3 m arena)
move it by only about 0.05-0.15, so a few places are off by tens of degrees (the method's known
weakness in cluttered scenes), and the engine's visual compass (``compass: visual``,
tests/compass_views.py) turns the current view back by its parallax error (up to 12.5 deg here,
see test_visual_compass). Measured on the 5 x 5 lattice: mean 25.7 deg with the visual compass
(22.7 deg on aligned views without it; with the mean threshold, seven sectors, 21.4 and 17.2);
the test allows 29 and 26. The papers' scene is tests/test_validation_alv.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from compass_views import WithVisualCompass, home_with_visual_compass
from landmark_scene import CROSS, landmark_view
from synthetic_panorama import home_errors, render, rolled

from homebench.geometry import Pose, angle_diff, angular_error, home_direction
from homebench.methods import registry
from homebench.methods.landmarks.alv import AverageLandmarkVector, average_landmark_vector
from homebench.methods.landmarks.horizon import Sectors

GOAL = Pose(0.2, -0.3, 0.4)
ORIGIN = Pose(0.0, 0.0, 0.0)


def _estimate(method, current_view, goal_view, compass="none"):
    if compass == "visual":
        return home_with_visual_compass(method, current_view, goal_view)
    return method.home(method.describe(current_view), method.describe(goal_view))


def test_the_alv_is_the_mean_unit_vector_to_the_landmarks():
    sectors = Sectors(np.array([0.0, math.pi / 2]), np.ones(2), np.ones(2, dtype=bool))
    np.testing.assert_allclose(average_landmark_vector(sectors), [0.5, 0.5], atol=1e-15)


@pytest.mark.parametrize("compass", ["visual", "none"])
@pytest.mark.parametrize(("dx", "dy"), [(0.3, 0.0), (-0.3, 0.0), (0.0, 0.3), (0.0, -0.2)])
def test_translation_along_x_and_y_in_the_symmetric_cross(compass, dx, dy):
    """The cross is symmetric about both axes and the panorama columns about 0 and 90 deg, so
    the ALV difference lies exactly along the displacement, pointing back (exact to rounding)."""
    method = AverageLandmarkVector()
    estimate = _estimate(method, landmark_view(Pose(dx, dy, 0.0)), landmark_view(ORIGIN), compass)
    assert angular_error(estimate.angle, math.atan2(-dy, -dx)) < 1e-9
    assert estimate.n_landmarks == 8
    if compass == "none":
        assert estimate.rotation is None
    else:  # parallax may tip the compass by a column; the goal's ALV is ~0 here, so no matter
        assert abs(estimate.rotation) <= 2.0 * math.pi / 288 + 1e-12


def test_bright_landmarks_are_the_gaps_of_the_cross():
    method = AverageLandmarkVector(landmarks="bright")
    estimate = _estimate(method, landmark_view(Pose(0.3, 0.0, 0.0)), landmark_view(ORIGIN))
    assert estimate.n_landmarks == 8  # four gaps in each view
    assert angular_error(estimate.angle, math.pi) < 1e-9


@pytest.mark.parametrize("k", [4, 90, 144, 250])
def test_a_current_view_turned_on_the_spot_keeps_the_world_direction(k):
    method = AverageLandmarkVector()
    current = render(Pose(GOAL.x - 0.5, GOAL.y + 0.4, 1.0))
    straight = _estimate(method, current, render(GOAL), "visual")
    turned = _estimate(method, rolled(current, k), render(GOAL), "visual")
    turn = -k * 2.0 * math.pi / 288  # rolled right by k columns: turned cw
    assert angular_error(turned.angle + turn, straight.angle) < 1e-9
    assert angular_error(turned.rotation, straight.rotation + turn) < 1e-9


@pytest.mark.parametrize("k", [0, 37])
def test_identical_or_turned_identical_views_give_no_direction(k):
    method = AverageLandmarkVector()
    goal = render(GOAL)
    estimate = _estimate(method, rolled(goal, k), goal, "visual")
    assert estimate.angle is None
    assert angular_error(estimate.rotation, -k * 2.0 * math.pi / 288) < 1e-9


def test_a_textureless_view_gives_no_estimate():
    method = AverageLandmarkVector()
    flat = np.full(288, 90.0)
    textured = method.describe(render(GOAL))
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None


@pytest.mark.parametrize(("compass", "tolerance_deg"), [("visual", 29.0), ("none", 26.0)])
def test_arena_lattice(compass, tolerance_deg):
    method = registry.create("alv")
    method = WithVisualCompass(method) if compass == "visual" else method
    errors = []
    for i in range(-2, 3):
        for j in range(-2, 3):
            if i == j == 0:
                continue
            current = Pose(GOAL.x + 0.3 * i, GOAL.y + 0.3 * j, GOAL.heading)
            angle_error, _, _ = home_errors(method, GOAL, current)
            errors.append(angle_error)
    assert np.mean(errors) < math.radians(tolerance_deg)


def test_an_asymmetric_scene_points_roughly_home():
    landmarks = np.array([[1.2, 0.3], [-0.4, 1.1], [-0.9, -0.8], [0.5, -1.3], [1.0, 1.0]])
    goal = landmark_view(ORIGIN, landmarks)
    method = AverageLandmarkVector()
    for pose in [Pose(0.2, 0.1, 0.5), Pose(-0.2, -0.15, -1.0)]:
        estimate = _estimate(method, landmark_view(pose, landmarks), goal, "visual")
        truth = home_direction(pose.xy, ORIGIN.xy, pose.heading)
        # ALV is exact only for symmetric scenes; here it errs by tens of degrees at most
        assert abs(float(angle_diff(estimate.angle, truth))) < math.radians(45.0)


def test_registered_with_the_papers_defaults():
    method = registry.create("alv")
    assert isinstance(method, AverageLandmarkVector)
    assert (method.landmarks, method.threshold) == ("dark", "otsu")
    assert CROSS.shape == (4, 2)
