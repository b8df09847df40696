"""KLT-sector homing end to end on the analytic arena.

Tolerance of the home direction: 10 deg. With exact bearings of ~60 features spread round the
goal the sector law itself is off by a few degrees at most (test_sector_law: median under 5 deg
with 100 landmarks; M is "not necessarily directed exactly towards G", section 2.1); tracking
errors of a few tenths of a pixel (test_klt_tracking) move a bearing by less than half a degree.
Errors measured on these pairs stay below 1.5 deg.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from synthetic_panorama import GEOMETRY, render, rolled

from homebench.errors import ConfigError
from homebench.geometry import PanoramaGeometry, Pose, angular_error, home_direction
from homebench.methods import registry
from homebench.methods.base import HomingEstimate, View
from homebench.methods.klt_sector.method import KltSector
from homebench.methods.klt_sector.tracking import KltTracker

TOLERANCE = math.radians(10.0)
GOAL = Pose(0.2, -0.3, 0.4)


def route_views(goal: Pose, current: Pose, step: float) -> list[Pose]:
    """Poses every ``step`` metres from the goal towards the current place, both excluded.

    The heading stays the goal's, as in a grid database; the current view may be turned.
    """
    n = math.ceil(math.dist(goal.xy, current.xy) / step)
    return [
        Pose(
            goal.x + (current.x - goal.x) * k / n,
            goal.y + (current.y - goal.y) * k / n,
            goal.heading,
        )
        for k in range(1, n)
    ]


def estimate(method: KltSector, current: Pose, step: float | None) -> HomingEstimate:
    route = [] if step is None else route_views(GOAL, current, step)
    return method.home(
        method.describe(render(current)),
        method.describe(render(GOAL)),
        [method.describe(render(pose)) for pose in route],
    )


def test_registered_with_a_route_flag():
    assert registry.get("klt-sector") is KltSector
    assert KltSector.uses_route is True
    params = registry.parameters("klt-sector")
    assert params["route_step"] == 0.5 and params["min_features"] == 3


@pytest.mark.parametrize(
    ("dx", "dy", "step"),
    [
        (0.3, 0.0, None),
        (-0.3, 0.0, None),
        (0.0, 0.3, None),
        (0.0, -0.3, None),
        (0.9, 0.0, 0.15),
        (-0.9, 0.0, 0.15),
        (0.0, 0.9, 0.15),
        (0.0, -0.9, 0.15),
        (1.0, 0.7, 0.15),
    ],
)
@pytest.mark.parametrize("heading", [0.4, -2.0])
def test_home_direction_along_x_and_y(dx, dy, step, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    # a turned current view (no compass) needs prealignment; an aligned one is the paper's case
    result = estimate(KltSector(prealign=heading != GOAL.heading), current, step)
    truth = home_direction(current.xy, GOAL.xy, heading)
    assert result.angle is not None and angular_error(result.angle, truth) < TOLERANCE
    assert result.n_landmarks >= 40
    assert result.diagnostics["route_length"] == (
        0 if step is None else len(route_views(GOAL, current, step))
    )
    assert not result.diagnostics["goal_reached"]


def test_goal_bisectors_also_home():
    current = Pose(GOAL.x - 0.6, GOAL.y, -1.0)
    result = estimate(KltSector(bisectors="goal", prealign=True), current, 0.15)
    truth = home_direction(current.xy, GOAL.xy, current.heading)
    assert angular_error(result.angle, truth) < TOLERANCE


@pytest.mark.parametrize("columns", [1, 45, -100, 144])
def test_a_turn_on_the_spot_is_recovered_to_one_column_and_counts_as_home(columns):
    method = KltSector(prealign=True)
    goal = render(GOAL)
    result = method.home(method.describe(rolled(goal, columns)), method.describe(goal))
    turn = -columns * GEOMETRY.column_step  # rolling right = turning clockwise
    assert angular_error(result.rotation, turn) <= GEOMETRY.column_step
    assert result.diagnostics["goal_reached"]


@pytest.mark.parametrize("columns", [45, 144])
def test_without_prealignment_a_big_turn_on_the_spot_is_lost(columns):
    method = KltSector()  # the paper's tracker: frame-rate steps, no turn of this size
    goal = render(GOAL)
    result = method.home(method.describe(rolled(goal, columns)), method.describe(goal))
    turn = -columns * GEOMETRY.column_step
    assert result.rotation is None or angular_error(result.rotation, turn) > GEOMETRY.column_step


def test_identical_views_give_no_direction_and_no_turn():
    method = KltSector()
    goal = method.describe(render(GOAL))
    result = method.home(goal, goal)
    assert result.angle is None and result.rotation == pytest.approx(0.0, abs=1e-9)


def test_the_linear_lcs_drops_features_that_cross_column_zero():
    """Turning the current view by 1 rad moves features across column 0, keeping their
    circular order: the circular reading keeps as many as without the turn, the linear fewer."""
    kept = {}
    for lcs in ("circular", "linear"):
        method = KltSector(prealign=True, lcs=lcs)
        for turn in (0.0, 1.0):
            current = Pose(GOAL.x + 0.2, GOAL.y, GOAL.heading + turn)
            kept[lcs, turn] = estimate(method, current, None).n_landmarks
    assert kept["circular", 1.0] >= kept["circular", 0.0] - 3
    assert kept["linear", 0.0] >= kept["circular", 0.0] - 3
    assert kept["linear", 1.0] < kept["circular", 1.0] - 5


def test_rotation_near_the_goal_is_the_heading_change():
    current = Pose(GOAL.x + 0.1, GOAL.y - 0.05, GOAL.heading - 1.3)
    result = estimate(KltSector(prealign=True), current, None)
    assert angular_error(result.rotation, -1.3) < math.radians(2.0)


def test_goal_threshold_decides_goal_reached():
    current = Pose(GOAL.x + 0.1, GOAL.y, GOAL.heading)
    near = estimate(KltSector(), current, None)
    assert not near.diagnostics["goal_reached"]
    relaxed = estimate(KltSector(goal_threshold=2.0 * near.score), current, None)
    assert relaxed.diagnostics["goal_reached"]


def test_too_few_features_give_no_estimate():
    method = KltSector(max_corners=2)
    result = method.home(method.describe(render(Pose(0.0, 0.1))), method.describe(render(GOAL)))
    assert result.angle is None and result.rotation is None and result.n_landmarks <= 2
    flat = View(np.full((GEOMETRY.height, GEOMETRY.width), 128, np.uint8), GEOMETRY)
    features = KltSector().describe(flat)
    assert len(features.corners) == 0
    assert KltSector().home(features, features).angle is None


def test_features_survive_pickling():
    features = KltSector().describe(render(GOAL))
    copy = pickle.loads(pickle.dumps(features))
    np.testing.assert_array_equal(copy.corners, features.corners)
    assert copy.geometry == GEOMETRY and len(features.corners) >= 50


def test_route_views_must_share_the_geometry():
    method = KltSector()
    other = PanoramaGeometry(288, 48, GEOMETRY.elevation_top, GEOMETRY.elevation_bottom, "cw")
    goal = method.describe(render(GOAL))
    odd = method.describe(View(render(GOAL).image, other))
    with pytest.raises(ValueError, match="geometry"):
        method.home(goal, goal, [odd])


@pytest.mark.parametrize(
    "params",
    [
        {"route_step": -1.0},
        {"min_features": 2},
        {"bisectors": "world"},
        {"fb_threshold": 0.0},
        {"lcs": "spiral"},
    ],
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        registry.create("klt-sector", **params)


def test_cached_route_prefixes_give_the_uncached_correspondences():
    """Currents sharing route views reuse the tracked prefix: same answer as from scratch."""
    method = KltSector()
    goal = method.describe(render(GOAL))
    far = Pose(GOAL.x + 0.9, GOAL.y + 0.3, GOAL.heading)
    route = [method.describe(render(pose)) for pose in route_views(GOAL, far, 0.15)]
    current = method.describe(render(far))
    cached = [method.correspondences(current, goal, route[:n]) for n in (2, 4, len(route))]
    assert len(method._route_tracks) == len(route) + 3  # each prefix, and each into current
    for n, (goal_xy, current_xy) in zip((2, 4, len(route)), cached, strict=True):
        fresh = KltSector().correspondences(current, goal, route[:n])
        np.testing.assert_array_equal(goal_xy, fresh[0])
        np.testing.assert_array_equal(current_xy, fresh[1])
    no_digest = [type(view)(view.image, view.geometry, view.corners) for view in route]
    uncached = KltSector()
    np.testing.assert_array_equal(
        uncached.correspondences(current, goal, no_digest)[1], cached[-1][1]
    )
    assert not uncached._route_tracks  # views without a digest are never cached


def test_a_current_on_the_route_to_a_farther_one_costs_no_tracking(monkeypatch):
    """The routes from a goal form a tree: each edge is tracked once, whatever the order."""
    method = KltSector()
    goal = method.describe(render(GOAL))
    far = Pose(GOAL.x + 0.9, GOAL.y + 0.3, GOAL.heading)
    views = [method.describe(render(pose)) for pose in route_views(GOAL, far, 0.15)]
    views.append(method.describe(render(far)))
    fresh = {n: KltSector().correspondences(views[n], goal, views[:n]) for n in (5, 1, 3)}
    steps = []
    step = KltTracker.step

    def counted(*args, **kwargs):
        steps.append(1)
        return step(*args, **kwargs)

    monkeypatch.setattr(KltTracker, "step", counted)
    method.correspondences(views[-1], goal, views[:-1])
    assert len(steps) == len(views)
    for n, (goal_xy, current_xy) in fresh.items():  # currents on the way, already reached
        near = method.correspondences(views[n], goal, views[:n])
        np.testing.assert_array_equal(near[0], goal_xy)
        np.testing.assert_array_equal(near[1], current_xy)
    assert len(steps) == len(views)  # not one step more


def test_route_views_need_no_corners_of_their_own():
    """``describe_route`` (what the engine uses for route views) skips corner detection and
    gives the answer of fully described route views: tracking reads only the goal's corners."""
    current = Pose(GOAL.x + 0.6, GOAL.y - 0.2, GOAL.heading)
    poses = route_views(GOAL, current, 0.15)
    bare = KltSector().describe_route(render(poses[0]))
    assert bare.corners.shape == (0, 2) and bare.digest
    assert bare.digest == KltSector().describe(render(poses[0])).digest
    described = estimate(KltSector(), current, 0.15)
    method = KltSector()
    routed = method.home(
        method.describe(render(current)),
        method.describe(render(GOAL)),
        [method.describe_route(render(pose)) for pose in poses],
    )
    assert routed.angle == described.angle and routed.n_landmarks == described.n_landmarks
    assert routed.rotation == described.rotation
