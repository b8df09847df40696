"""The sift method on rendered raw catadioptric views of a generated world.

Tolerances, measured on worlds 0-2 (5 x 5 grid), 12 offsets of 0.3-1.2 m and three heading
conditions (108 pairs per variant): the home direction's error had a median of 3.5-3.7 deg and a
maximum of 15 deg (P) / 20 deg (PN), mostly where near furniture and floor tiles break the
equal-distance assumption most. Pairs are held to 25 deg: well inside the 90 deg that still
brings a robot nearer, and far from what a mirrored axis or a flipped sign gives (about
180 deg on one of the four axis directions). The heading change, which rests less on the
equal-distance assumption, stayed within 2 deg (P) / 3 deg (PN) and is held to 5 deg.
"""

from __future__ import annotations

import math

import pytest

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import build_world
from homebench.geometry import Pose, angular_error, home_direction
from homebench.imaging.rotation import rotate_view
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.sift import SiftFeatures

SPEC = WorldSpec(seed=0, grid={"shape": [5, 5]})
GOAL = SPEC.to_grid().position(2, 2)
GOAL_HEADING = 0.4
METHODS = {
    "P": registry.create("sift"),
    "PN": registry.create("sift", horizon_constraint=False, half_plane_constraint=False),
}
ANGLE_TOLERANCE = math.radians(25.0)
ROTATION_TOLERANCE = math.radians(5.0)


def _view(x: float, y: float, heading: float) -> View:
    image = build_world(SPEC).render(Pose(x, y, heading), noise_seed=1)["raw"]
    return View(image, SPEC.raw.geometry())


@pytest.fixture(scope="module")
def goal_features() -> SiftFeatures:
    return METHODS["P"].describe(_view(GOAL[0], GOAL[1], GOAL_HEADING))


@pytest.mark.parametrize("label", ["P", "PN"])
@pytest.mark.parametrize(
    ("offset", "heading", "turn"),
    [
        ((0.3, 0.0), GOAL_HEADING, 0.0),
        ((-0.6, 0.0), -1.2, 0.0),
        ((0.0, 0.9), GOAL_HEADING, 0.0),
        ((0.0, -1.2), 2.5, 0.0),
        ((0.6, -0.6), GOAL_HEADING, 1.5),  # a rendered view, then turned on the spot
    ],
)
def test_home_direction_on_rendered_raw_views(goal_features, label, offset, heading, turn):
    method = METHODS[label]
    current_xy = (GOAL[0] + offset[0], GOAL[1] + offset[1])
    view = rotate_view(_view(*current_xy, heading), turn) if turn else _view(*current_xy, heading)
    estimate = method.home(method.describe(view), goal_features)
    assert estimate.angle is not None and estimate.n_landmarks >= 50
    truth = home_direction(current_xy, GOAL, heading + turn)
    assert angular_error(estimate.angle, truth) < ANGLE_TOLERANCE
    assert angular_error(estimate.rotation, heading + turn - GOAL_HEADING) < ROTATION_TOLERANCE


def test_elimination_removes_some_matches(goal_features):
    view = _view(GOAL[0] - 0.9, GOAL[1] + 0.3, GOAL_HEADING)
    estimate = METHODS["P"].home(METHODS["P"].describe(view), goal_features)
    counts = estimate.diagnostics
    assert counts["n_matches"] > counts["n_after_horizon"] >= counts["n_after_half_plane"]
    assert counts["n_after_half_plane"] == estimate.n_landmarks
