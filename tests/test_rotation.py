"""rotate_view moves scene content the way a robot turning on the spot sees it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry, angle_diff
from homebench.imaging.rotation import rotate_view
from homebench.methods.base import View


def _brightest_azimuth_raw(image: np.ndarray, geometry: CatadioptricGeometry) -> float:
    v, u = np.unravel_index(np.argmax(image), image.shape)
    return float(geometry.pixel_to_bearing(u, v)[0])


@pytest.mark.parametrize("direction", ["ccw", "cw"])
def test_unfolded_rotation_moves_landmark_to_smaller_azimuth(direction: str) -> None:
    g = PanoramaGeometry(72, 10, 0.5, -0.5, direction)
    image = np.zeros((10, 72), np.uint8)
    landmark_azimuth = math.radians(100)
    image[:, round(float(g.azimuth_to_column(landmark_azimuth)))] = 255
    turned = rotate_view(View(image, g), math.radians(30))
    column = int(np.argmax(turned.image[0]))
    assert float(g.column_to_azimuth(column)) == pytest.approx(math.radians(70))


def test_unfolded_rotation_rejects_fractional_columns() -> None:
    g = PanoramaGeometry(72, 10, 0.5, -0.5)
    with pytest.raises(ValueError):
        rotate_view(View(np.zeros((10, 72), np.uint8), g), math.radians(2))


@pytest.mark.parametrize("direction", ["ccw", "cw"])
def test_raw_rotation_moves_landmark_to_smaller_azimuth(direction: str) -> None:
    g = CatadioptricGeometry(
        201, 161, (100.0, 80.0), (10.0, 75.0), (-0.8, 0.7), direction, math.radians(90)
    )
    image = np.zeros((161, 201), np.uint8)
    u, v = g.bearing_to_pixel(math.radians(100), 0.3)
    image[round(float(v)) - 1 : round(float(v)) + 2, round(float(u)) - 1 : round(float(u)) + 2] = (
        255
    )
    turned = rotate_view(View(image, g), math.radians(30))
    measured = _brightest_azimuth_raw(turned.image, g)
    assert abs(float(angle_diff(measured, math.radians(70)))) < math.radians(3)
