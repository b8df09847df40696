"""Visual compass: the RIDF, its minimum, sub-column refinement, the arena.

Arena tolerance: the wall is 2.2-3.8 m from the goal and the lattice reaches 0.85 m from it, so
the wall's texture shifts in azimuth by up to ~13 deg between the views, differently in every
direction (parallax); the RIDF minimum settles on a compromise of those shifts. Measured on the
5 x 5 lattice: mean rotation error 6.0 deg, max 12.5 deg; the test allows 8 and 15.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import GEOMETRY, home_errors, render, rolled

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.visual_compass import (
    VisualCompass,
    compass_image,
    compass_rotation,
    minimum_shift,
    ridf,
)

GOAL = Pose(0.2, -0.3, 0.4)
COLUMN = 2.0 * math.pi / GEOMETRY.width


def test_ridf_is_the_rms_difference_of_every_roll():
    rng = np.random.default_rng(1)
    current, goal = rng.uniform(0, 255, (3, 12)), rng.uniform(0, 255, (3, 12))
    expected = [np.sqrt(np.mean((np.roll(current, s, axis=-1) - goal) ** 2)) for s in range(12)]
    np.testing.assert_allclose(ridf(current, goal), expected, rtol=1e-12)


@pytest.mark.parametrize("k", [1, 5, 100, 144, 287])
def test_a_roll_by_whole_columns_is_found_exactly(k):
    goal = render(GOAL)
    method = VisualCompass()
    estimate = method.home(method.describe(rolled(goal, k)), method.describe(goal))
    # rolling the image right by k columns turns the robot cw by k columns (ccw panorama)
    assert angular_error(estimate.rotation, -k * COLUMN) < 1e-9
    assert estimate.angle is None
    assert estimate.score == pytest.approx(0.0, abs=1e-6)
    assert compass_rotation(method.describe(rolled(goal, k)), method.describe(goal)) == (
        estimate.rotation
    )


def test_parabolic_refinement_finds_a_fraction_of_a_column():
    n = 72
    phi = 2.0 * np.pi * np.arange(n) / n
    goal = np.cos(phi) + 0.5 * np.sin(2.0 * phi)
    current = np.cos(phi + 0.3 * 2 * np.pi / n) + 0.5 * np.sin(2.0 * (phi + 0.3 * 2 * np.pi / n))
    # current[k] = goal[k + 0.3]: the best whole shift is 0, the refined one 0.3 columns; a
    # parabola through a smooth minimum (two harmonics) is right to a few thousandths
    assert minimum_shift(ridf(current, goal)) == 0.0
    assert minimum_shift(ridf(current, goal), interpolate=True) == pytest.approx(0.3, abs=0.005)
    rotation = compass_rotation(current, goal, interpolate=True)
    assert rotation == pytest.approx(0.3 * 2 * np.pi / n, abs=0.005 * 2 * np.pi / n)


def test_parabolic_refinement_keeps_a_flat_minimum():
    assert minimum_shift(np.full(4, 3.0), interpolate=True) == 0.0
    # a plateau of two columns: the vertex lies midway between them
    assert minimum_shift(np.array([3.0, 3.0, 4.0, 5.0]), interpolate=True) == 0.5


def test_identical_views_give_rotation_zero():
    method = VisualCompass()
    image = method.describe(render(GOAL))
    estimate = method.home(image, image)
    assert estimate.rotation == 0.0 and estimate.angle is None


def test_a_textureless_view_gives_no_estimate():
    method = VisualCompass()
    flat = np.full((48, 288), 90.0)
    textured = method.describe(render(GOAL))
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None
    assert compass_rotation(flat, flat) == 0.0


def test_describe_gives_canonical_columns_whatever_the_database_layout():
    view = render(GOAL)
    mirrored = View(  # the same panorama stored clockwise, zero column 10
        np.roll(view.image[:, ::-1], 10 - 287, axis=1),
        type(GEOMETRY)(288, 48, GEOMETRY.elevation_top, GEOMETRY.elevation_bottom, "cw", 10.0),
    )
    np.testing.assert_allclose(compass_image(mirrored), compass_image(view), atol=1e-9)
    assert compass_image(view).shape == (48, 288)
    band = compass_image(view, (-5.0, 5.0))
    assert band.shape == (8, 288)  # 10 deg of 1.25 deg rows


def test_arena_lattice_rotation_errors():
    method = registry.create("visual-compass")
    errors = []
    for i in range(-2, 3):
        for j in range(-2, 3):
            current = Pose(GOAL.x + 0.3 * i, GOAL.y + 0.3 * j, GOAL.heading + 0.6)
            angle_error, rotation_error, _ = home_errors(method, GOAL, current)
            assert angle_error is None
            errors.append(rotation_error)
    assert np.mean(errors) < math.radians(8.0)
    assert np.max(errors) < math.radians(15.0)


@pytest.mark.parametrize("band", [(5.0, -5.0), (1.0, 1.0), (0.0,)])
def test_bad_bands_are_config_errors(band):
    with pytest.raises(ConfigError, match="elevation_range_deg"):
        VisualCompass(elevation_range_deg=band)


def test_registered_with_the_papers_defaults():
    method = registry.create("visual-compass")
    assert isinstance(method, VisualCompass)
    assert method.elevation_range_deg is None and method.interpolate is False
