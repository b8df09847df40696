"""Snapshot model: the pair vectors, symmetric scenes, rotation, degenerate inputs, the arena.

Arena tolerance: each sector pair votes with unit vectors whatever its mismatch, and about 10
pairs (dark and bright, Otsu's threshold on the arena's grey wall) share the vote, so a sector
that splits or vanishes between the views tips the sum by a few degrees; the engine's visual
compass's parallax error (``compass: visual``, tests/compass_views.py; up to 12.5 deg here, see
test_visual_compass) makes pairs whose bearings already agreed vote tangentially. Measured on
the 5 x 5 lattice: mean 8.9 deg with the visual compass, 5.8 deg on aligned views without it
(the mean threshold: 11.6 and 5.7); the test allows 15 and 10. The papers' scene is
tests/test_validation_snapshot.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from compass_views import WithVisualCompass, home_with_visual_compass
from landmark_scene import landmark_view
from synthetic_panorama import home_errors, render, rolled

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error
from homebench.methods import registry
from homebench.methods.landmarks.horizon import Sectors
from homebench.methods.landmarks.snapshot import SnapshotModel, pair_sectors, snapshot_vectors

GOAL = Pose(0.2, -0.3, 0.4)
ORIGIN = Pose(0.0, 0.0, 0.0)
DEG = math.pi / 180.0


def _sectors(centres_deg, widths, dark):
    return Sectors(np.radians(centres_deg), np.asarray(widths, float), np.asarray(dark))


def _estimate(method, current_view, goal_view, compass="none"):
    if compass == "visual":
        return home_with_visual_compass(method, current_view, goal_view)
    return method.home(method.describe(current_view), method.describe(goal_view))


def test_pairs_join_the_nearest_sector_of_the_same_kind():
    snapshot = _sectors([0.0, 90.0, 180.0], [1, 1, 1], [True, False, True])
    current = _sectors([80.0, 100.0, 10.0, 170.0], [1, 1, 1, 1], [True, False, True, False])
    snap, now = pair_sectors(snapshot, current)
    assert snap.tolist() == [0, 1, 2] and now.tolist() == [2, 1, 0]
    none_bright = _sectors([80.0], [1], [True])
    assert pair_sectors(snapshot, none_bright)[0].tolist() == [0, 2]


def test_one_pair_votes_tangentially_and_radially():
    # a landmark seen at 100 deg, 0.1 rad wide, was at 90 deg, 0.2 rad wide in the snapshot:
    # turn its bearing down (cw) by moving to its left (bearing + 90 deg) and approach it
    snapshot = _sectors([90.0], [0.2], [True])
    current = _sectors([100.0], [0.1], [True])
    tangential, radial, pairs = snapshot_vectors(snapshot, current)
    np.testing.assert_allclose(tangential, [math.cos(190 * DEG), math.sin(190 * DEG)])
    np.testing.assert_allclose(radial, [math.cos(100 * DEG), math.sin(100 * DEG)])
    assert pairs == 1
    # larger than in the snapshot, bearing already right: move away, no tangential vote
    tangential, radial, _ = snapshot_vectors(snapshot, _sectors([90.0], [0.3], [True]))
    np.testing.assert_allclose(tangential, [0.0, 0.0])
    np.testing.assert_allclose(radial, [0.0, -1.0], atol=1e-15)


@pytest.mark.parametrize("compass", ["visual", "none"])
@pytest.mark.parametrize(("dx", "dy"), [(0.3, 0.0), (-0.3, 0.0), (0.0, 0.3), (0.0, -0.2)])
def test_translation_along_x_and_y_in_the_symmetric_cross(compass, dx, dy):
    """Mirror symmetry about the displacement's axis cancels every vote across it; the votes
    along it point back to the goal (exact to rounding)."""
    method = SnapshotModel()
    estimate = _estimate(method, landmark_view(Pose(dx, dy, 0.0)), landmark_view(ORIGIN), compass)
    assert angular_error(estimate.angle, math.atan2(-dy, -dx)) < 1e-9
    assert estimate.n_landmarks == 8  # four dark and four bright sectors paired


@pytest.mark.parametrize("k", [4, 90, 144, 250])
def test_a_current_view_turned_on_the_spot_keeps_the_world_direction(k):
    method = SnapshotModel()
    current = render(Pose(GOAL.x - 0.5, GOAL.y + 0.4, 1.0))
    straight = _estimate(method, current, render(GOAL), "visual")
    turned = _estimate(method, rolled(current, k), render(GOAL), "visual")
    turn = -k * 2.0 * math.pi / 288  # rolled right by k columns: turned cw
    assert angular_error(turned.angle + turn, straight.angle) < 1e-9
    assert angular_error(turned.rotation, straight.rotation + turn) < 1e-9


@pytest.mark.parametrize("k", [0, 37])
def test_identical_or_turned_identical_views_give_no_direction(k):
    method = SnapshotModel()
    goal = render(GOAL)
    estimate = _estimate(method, rolled(goal, k), goal, "visual")
    assert estimate.angle is None and estimate.n_landmarks > 0
    assert angular_error(estimate.rotation, -k * 2.0 * math.pi / 288) < 1e-9


def test_a_textureless_view_gives_no_estimate():
    method = SnapshotModel()
    flat = np.full(288, 90.0)
    textured = method.describe(render(GOAL))
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None


def test_weights_scale_the_two_kinds_of_vote():
    current = landmark_view(Pose(0.25, 0.15, 0.0))
    goal = landmark_view(ORIGIN)
    only_radial = _estimate(SnapshotModel(tangential_weight=0.0), current, goal)
    only_tangential = _estimate(SnapshotModel(radial_weight=0.0), current, goal)
    tangential, radial = (np.array(only_radial.diagnostics[k]) for k in ("tangential", "radial"))
    assert only_radial.angle == pytest.approx(math.atan2(radial[1], radial[0]))
    assert only_tangential.angle == pytest.approx(math.atan2(tangential[1], tangential[0]))


@pytest.mark.parametrize(("compass", "tolerance_deg"), [("visual", 15.0), ("none", 10.0)])
def test_arena_lattice(compass, tolerance_deg):
    method = registry.create("snapshot")
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


@pytest.mark.parametrize(
    "params", [{"tangential_weight": -1.0}, {"tangential_weight": 0.0, "radial_weight": 0.0}]
)
def test_bad_weights_are_config_errors(params):
    with pytest.raises(ConfigError, match="snapshot"):
        SnapshotModel(**params)


def test_registered_with_unit_weights():
    method = registry.create("snapshot")
    assert isinstance(method, SnapshotModel)
    assert (method.tangential_weight, method.radial_weight) == (1.0, 1.0)
