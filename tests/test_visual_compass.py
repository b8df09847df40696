"""Visual compass: the RIDF, its minimum, sub-column refinement, the arena.

Arena tolerance: the wall is 2.2-3.8 m from the goal and the lattice reaches 0.85 m from it, so
the wall's texture shifts in azimuth by up to ~13 deg between the views, differently in every
direction (parallax); the RIDF minimum settles on a compromise of those shifts. Measured on the
5 x 5 lattice: mean rotation error 6.0 deg, max 12.5 deg; the test allows 8 and 15.

The papers' own scene, the method's validation: tests/test_validation_visual_compass.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import GEOMETRY, home_errors, render

from homebench.errors import ConfigError
from homebench.geometry import Pose
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.image_difference.visual_compass import (
    VisualCompass,
    compass_image,
    compass_rotation,
    low_pass,
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


@pytest.mark.parametrize("cycles", [1, 3, 10])
def test_low_pass_is_a_gaussian_that_wraps_round_in_azimuth(cycles):
    """A sinusoid of ``cycles`` per turn keeps its phase, its amplitude falls by the Gaussian's
    transfer exp(-(sigma * cycles)**2 / 2) (sigma in radians), the seam included."""
    phi = 2.0 * np.pi * np.arange(288) / 288
    image = np.tile(np.cos(cycles * phi + 0.3), (5, 1))
    blurred = low_pass(image, 5.0, COLUMN, COLUMN)
    gain = math.exp(-((math.radians(5.0) * cycles) ** 2) / 2.0)
    np.testing.assert_allclose(blurred, gain * image, atol=1e-4)
    assert low_pass(image, None, COLUMN, COLUMN) is image
    assert low_pass(image, 0.0, COLUMN, COLUMN) is image


@pytest.mark.parametrize("name", ["visual-compass", "mfdid", "did"])
def test_blur_is_off_by_default_and_checked(name):
    view = render(GOAL)
    method = registry.create(name)
    assert method.blur_deg is None
    np.testing.assert_array_equal(method.describe(view), compass_image(view))
    sharp, blurred = compass_image(view), registry.create(name, blur_deg=3.0).describe(view)
    assert blurred.shape == sharp.shape
    assert np.abs(np.diff(blurred)).mean() < 0.9 * np.abs(np.diff(sharp)).mean()
    with pytest.raises(ConfigError, match=f"{name}: blur_deg"):
        registry.create(name, blur_deg=-1.0)
