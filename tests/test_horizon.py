"""Horizon band extraction: canonical column order, row averaging, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import GEOMETRY, render

from homebench.errors import ConfigError
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry, Pose
from homebench.imaging.horizon import (
    band_elevations,
    canonical_columns,
    horizon_band,
    horizon_signal,
    row_weights,
)


def _signal(azimuth: np.ndarray) -> np.ndarray:
    """A band-limited periodic test signal of the azimuth (highest frequency 5 cycles/turn)."""
    return np.cos(3.0 * azimuth) + 0.5 * np.sin(azimuth + 0.3) - 0.2 * np.cos(5.0 * azimuth)


@pytest.mark.parametrize("direction", ["ccw", "cw"])
@pytest.mark.parametrize("zero_column", [0.0, 17.0, 101.4])
@pytest.mark.parametrize("n_columns", [72, 96, 288, 360])
def test_canonical_columns_put_azimuth_2pik_over_n_at_column_k(direction, zero_column, n_columns):
    geometry = PanoramaGeometry(288, 4, 0.3, -0.3, direction=direction, zero_column=zero_column)
    values = _signal(geometry.column_to_azimuth(np.arange(288)))
    out = canonical_columns(np.stack([values, 2.0 * values]), geometry, n_columns)
    expected = _signal(2.0 * np.pi * np.arange(n_columns) / n_columns)
    assert out.shape == (2, n_columns)
    np.testing.assert_allclose(out[0], expected, atol=1e-9)
    np.testing.assert_allclose(out[1], 2.0 * expected, atol=1e-9)


def test_canonical_columns_is_an_exact_roll_for_whole_zero_columns():
    geometry = PanoramaGeometry(10, 1, 0.1, -0.1, zero_column=3.0)
    values = np.arange(10.0) ** 2  # not band-limited: a resampler would alter it
    np.testing.assert_array_equal(canonical_columns(values, geometry), np.roll(values, -3))


def test_canonical_columns_rejects_a_wrong_width():
    with pytest.raises(ValueError, match="columns"):
        canonical_columns(np.zeros(10), GEOMETRY)


def test_row_weights_average_exactly_the_rows_in_the_band():
    geometry = PanoramaGeometry(8, 12, math.radians(30), math.radians(-30))  # 5 deg per row
    weights = row_weights(geometry, math.radians(-10), math.radians(10), 2)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0)
    expected = np.zeros((2, 12))
    expected[0, 4:6] = 0.5  # rows 4 and 5 span +10 .. 0 deg
    expected[1, 6:8] = 0.5
    np.testing.assert_allclose(weights, expected, atol=1e-12)


def test_band_elevations_are_row_centres():
    np.testing.assert_allclose(band_elevations(-1.0, 1.0, 4), [0.75, 0.25, -0.25, -0.75])


def test_horizon_signal_is_the_band_mean_of_an_elevation_ramp():
    geometry = PanoramaGeometry(16, 60, math.radians(30), math.radians(-30))
    elevation = geometry.row_to_elevation(np.arange(60))
    image = np.broadcast_to((100.0 + 100.0 * elevation)[:, None], (60, 16))
    # symmetric band over a linear ramp: the mean is the value at the horizon
    np.testing.assert_allclose(horizon_signal(image, geometry, math.radians(5), 8), 100.0)


def test_band_outside_the_panorama_is_a_config_error():
    with pytest.raises(ConfigError, match="outside"):
        horizon_band(np.zeros((48, 288)), GEOMETRY, math.radians(-40), 0.1, 4, 96)


def test_raw_views_have_no_horizon_band():
    raw = CatadioptricGeometry(64, 64, (32.0, 32.0), (5.0, 30.0), (-0.5, 0.5))
    with pytest.raises(ConfigError, match="unfolded"):
        horizon_band(np.zeros((64, 64)), raw, -0.1, 0.1, 1, 16)  # type: ignore[arg-type]


def test_cw_and_ccw_panoramas_of_one_pose_give_one_horizon():
    pose = Pose(0.4, -0.7, 1.1)
    other = PanoramaGeometry(
        360, 60, math.radians(30), math.radians(-30), direction="cw", zero_column=45.0
    )
    a = render(pose)
    b = render(pose, other)
    band_a = horizon_band(a.image, a.geometry, math.radians(-10), math.radians(10), 4, 72)
    band_b = horizon_band(b.image, b.geometry, math.radians(-10), math.radians(10), 4, 72)
    assert np.max(np.abs(band_a - band_b)) < 3.0  # grey levels; rounding and resampling only
