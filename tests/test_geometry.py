"""Conventions of homebench.geometry, checked against hand-computed answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.geometry import (
    CatadioptricGeometry,
    Grid,
    PanoramaGeometry,
    Pose,
    angle_diff,
    angular_error,
    circular_mean,
    grid_key,
    home_direction,
    parse_grid_key,
    robot_to_world,
    world_direction,
    world_to_robot,
    wrap_angle,
    wrap_positive,
)


def test_wrap_angle_range_and_identity() -> None:
    a = np.linspace(-20, 20, 4001)
    w = wrap_angle(a)
    assert np.all(w >= -np.pi) and np.all(w < np.pi)
    np.testing.assert_allclose(np.sin(w), np.sin(a), atol=1e-12)
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-12)
    assert wrap_angle(np.pi) == pytest.approx(-np.pi)
    assert wrap_positive(-0.5) == pytest.approx(2 * np.pi - 0.5)


def test_angle_diff_and_error_cross_the_seam() -> None:
    assert angle_diff(math.radians(179), math.radians(-179)) == pytest.approx(math.radians(-2))
    assert angular_error(math.radians(-179), math.radians(179)) == pytest.approx(math.radians(2))
    assert angular_error(0.0, np.pi) == pytest.approx(np.pi)


def test_circular_mean_wraps_and_empty_is_nan() -> None:
    assert circular_mean(np.radians([350, 10])) == pytest.approx(0.0, abs=1e-12)
    assert math.isnan(circular_mean([]))


@pytest.mark.parametrize(
    ("goal", "expected_world"),
    [((1.0, 0.0), 0.0), ((-1.0, 0.0), np.pi), ((0.0, 1.0), np.pi / 2), ((0.0, -1.0), -np.pi / 2)],
)
def test_world_direction_along_both_axes(goal: tuple[float, float], expected_world: float) -> None:
    assert angular_error(world_direction((0.0, 0.0), goal), expected_world) < 1e-12


def test_home_direction_in_robot_frame() -> None:
    # Goal straight ahead of a robot facing +y: azimuth 0; to its left (-x): +90 deg (ccw).
    heading = np.pi / 2
    assert angular_error(home_direction((0, 0), (0, 2), heading), 0.0) < 1e-12
    assert angular_error(home_direction((0, 0), (-2, 0), heading), np.pi / 2) < 1e-12
    assert angular_error(home_direction((0, 0), (2, 0), heading), -np.pi / 2) < 1e-12


def test_robot_world_round_trip() -> None:
    az = np.linspace(-3, 3, 7)
    np.testing.assert_allclose(world_to_robot(robot_to_world(az, 1.2), 1.2), az, atol=1e-12)


def test_pose_bearing_to_points() -> None:
    pose = Pose(1.0, 2.0, heading=np.pi / 2)
    az, el = pose.bearing_to(np.array([[1.0, 3.0, 1.0], [0.0, 2.0, 2.0]]), camera_height=1.0)
    np.testing.assert_allclose(az, [0.0, np.pi / 2], atol=1e-12)
    np.testing.assert_allclose(el, [0.0, np.pi / 4], atol=1e-12)


def test_grid_positions_keys_and_nearest() -> None:
    grid = Grid((10, 17), 0.3, (0.5, 1.0))
    np.testing.assert_allclose(grid.position(2, 3), [1.1, 1.9])
    assert tuple(grid.nearest_index([1.14, 1.86])) == (2, 3)
    assert tuple(grid.nearest_index([-5.0, 99.0])) == (0, 16)
    assert grid.contains(9, 16) and not grid.contains(10, 0)
    assert grid.perimeter == pytest.approx(2 * (9 + 16) * 0.3)
    assert list(grid.indices())[:2] == [(0, 0), (0, 1)]
    assert parse_grid_key(grid_key(7, 13)) == (7, 13)
    with pytest.raises(ValueError):
        Grid((0, 3), 0.3)


def test_a_grid_with_holes_leaves_them_out_and_steers_to_the_nearest_present() -> None:
    import pickle

    from homebench.geometry import HoledGrid, holed_grid, missing_positions

    full = Grid((4, 3), 0.5, (1.0, -1.0))
    assert holed_grid((4, 3), 0.5, (1.0, -1.0), []) == full  # no holes: a Grid, as before
    assert repr(holed_grid((4, 3), 0.5, (1.0, -1.0), [])) == repr(full)
    grid = holed_grid((4, 3), 0.5, (1.0, -1.0), [(2, 1), (0, 0), (2, 1)])
    assert isinstance(grid, HoledGrid) and missing_positions(grid) == ((0, 0), (2, 1))
    assert grid.size == 10 and len(list(grid.indices())) == 10 and missing_positions(full) == ()
    assert not grid.contains(2, 1) and grid.contains(2, 2) and not grid.contains(4, 0)
    assert (2, 1) not in set(grid.indices()) and grid.present().sum() == 10
    np.testing.assert_allclose(grid.position(2, 1), [2.0, -0.5])  # where it would be
    assert tuple(grid.nearest_index([2.05, -0.45])) in {(1, 1), (3, 1), (2, 0), (2, 2)}
    assert tuple(grid.nearest_index([2.05, -0.3])) == (2, 2)
    assert tuple(grid.nearest_index([0.9, -1.1])) in {(1, 0), (0, 1)}  # off the grid too
    np.testing.assert_array_equal(grid.nearest_index([[1.5, -1.0], [2.5, 0.0]]), [[1, 0], [3, 2]])
    assert grid != full and grid == holed_grid((4, 3), 0.5, (1.0, -1.0), [(2, 1), (0, 0)])
    copy = pickle.loads(pickle.dumps(grid))
    assert copy == grid and hash(copy) == hash(grid)
    with pytest.raises(ValueError, match="inside"):
        HoledGrid((4, 3), 0.5, (0.0, 0.0), ((4, 0),))
    with pytest.raises(ValueError, match="misses 1 to all but one"):
        HoledGrid((1, 2), 0.5, (0.0, 0.0), ((0, 0), (0, 1)))


@pytest.mark.parametrize("direction", ["ccw", "cw"])
def test_panorama_columns_and_rows(direction: str) -> None:
    g = PanoramaGeometry(360, 95, math.radians(45), math.radians(-50), direction, zero_column=10)
    cols = np.arange(360.0)
    np.testing.assert_allclose(g.azimuth_to_column(g.column_to_azimuth(cols)), cols, atol=1e-9)
    assert g.column_to_azimuth(10) == pytest.approx(0.0)
    sign = 1 if direction == "ccw" else -1
    assert g.column_to_azimuth(100) == pytest.approx(sign * np.pi / 2)
    # rows: the horizon (elevation 0) lies 45 rows below the top edge
    assert g.horizon_row == pytest.approx(45 - 0.5)
    assert g.row_to_elevation(-0.5) == pytest.approx(math.radians(45))
    assert g.row_to_elevation(94.5) == pytest.approx(math.radians(-50))
    # rotating the robot ccw by one column step moves the scene cw in a ccw panorama
    assert g.columns_for_rotation(g.column_step) == pytest.approx(-sign)


def _raw(direction: str = "cw") -> CatadioptricGeometry:
    return CatadioptricGeometry(
        752, 564, (375.5, 281.5), (25.0, 270.0), (math.radians(-50), math.radians(45)),
        direction, zero_angle=math.radians(90),
    )  # fmt: skip


@pytest.mark.parametrize("direction", ["ccw", "cw"])
def test_catadioptric_round_trip(direction: str) -> None:
    g = _raw(direction)
    rng = np.random.default_rng(0)
    az = rng.uniform(-np.pi, np.pi, 500)
    el = rng.uniform(math.radians(-50), math.radians(45), 500)
    u, v = g.bearing_to_pixel(az, el)
    az2, el2 = g.pixel_to_bearing(u, v)
    np.testing.assert_allclose(angle_diff(az2, az), 0.0, atol=1e-9)
    np.testing.assert_allclose(el2, el, atol=1e-9)


def test_catadioptric_orientation_and_horizon() -> None:
    g = _raw("cw")
    # azimuth 0 (ahead) appears straight up in the image; +90 deg (left) to the right (cw mirror)
    u, v = g.bearing_to_pixel(0.0, 0.0)
    assert u == pytest.approx(375.5) and v < 281.5
    u, v = g.bearing_to_pixel(np.pi / 2, 0.0)
    assert u > 375.5 and v == pytest.approx(281.5)
    assert g.horizon_radius == pytest.approx(25 + 50 / 95 * 245)
    assert g.up_is_outside
    radii = np.array([30.0, 260.0, g.horizon_radius + 0.4])
    sides = g.horizon_side(375.5 + radii, np.full(3, 281.5), tolerance=0.5)
    assert sides.tolist() == [-1, 1, 0]


def test_catadioptric_rejects_bad_profiles() -> None:
    with pytest.raises(ValueError):
        CatadioptricGeometry(10, 10, (5, 5), (1.0, 1.0), (-0.1, 0.1))
    with pytest.raises(ValueError):
        CatadioptricGeometry(10, 10, (5, 5), (1.0, 4.0), (0.1, 0.2))


def test_places_address_posed_images_as_k_0() -> None:
    import pickle

    from homebench.geometry import Places, is_places

    places = Places.of([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [1.0, 2.0]])
    assert places.shape == (4, 1) and is_places(places) and not is_places(Grid((4, 1), 1.0))
    assert list(places.indices()) == [(0, 0), (1, 0), (2, 0), (3, 0)]
    assert places.contains(3, 0) and not places.contains(4, 0) and not places.contains(0, 1)
    np.testing.assert_array_equal(places.position(2, 0), [1.0, 2.0])
    np.testing.assert_array_equal(places.position([1, 0], [0, 0]), [[1.0, 0.0], [0.0, 0.0]])
    np.testing.assert_array_equal(places.nearest_index([[0.9, 0.2], [0.1, 0.0]]), [[1, 0], [0, 0]])
    assert places.spacing == 1.0  # median nearest distance, the coincident pair left out
    assert places != Grid((4, 1), 1.0, (0.0, 0.0)) and places == Places.of(places.points)
    copy = pickle.loads(pickle.dumps(places))
    assert copy == places and hash(copy) == hash(places)
    assert Places.of([[3.0, 4.0]]).spacing == 1.0 and Places.of([[0, 0], [0, 0]]).spacing == 1.0
    assert Places.of([[0.0, 0.0], [1e308, 0.0], [-1e308, 0.0]]).spacing == 1.0
    with pytest.raises(ValueError, match="finite"):
        Places.of([[0.0, np.nan]])
