"""Camera models turned in azimuth, their horizon moved, their direction mirrored (the
corrections data check proposes are made with these)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.geometry import (
    CatadioptricGeometry,
    PanoramaGeometry,
    angle_diff,
    other_direction,
)

PANORAMA = PanoramaGeometry(360, 95, math.radians(45), math.radians(-50), "cw", 72.0)
RAW = CatadioptricGeometry(
    752, 564, (375.5, 281.5), (25.0, 270.0), (math.radians(-50), math.radians(45)), "cw", 1.5
)


@pytest.mark.parametrize("direction", ["ccw", "cw"])
@pytest.mark.parametrize("offset", [0.3, -2.0, math.pi])
def test_turned_models_add_the_offset_to_every_azimuth(direction: str, offset: float) -> None:
    pano = PanoramaGeometry(360, 95, 0.5, -0.5, direction, 72.0)
    columns = np.arange(0, 360, 7.5)
    turned = pano.turned(offset)
    assert 0 <= turned.zero_column < 360
    np.testing.assert_allclose(
        angle_diff(turned.column_to_azimuth(columns), pano.column_to_azimuth(columns) + offset),
        0,
        atol=1e-9,
    )
    raw = CatadioptricGeometry(100, 80, (50, 40), (5, 35), (-0.8, 0.7), direction, 1.0)
    u, v = np.array([60.0, 20.0, 50.0]), np.array([40.0, 10.0, 75.0])
    before, _ = raw.pixel_to_bearing(u, v)
    after, _ = raw.turned(offset).pixel_to_bearing(u, v)
    np.testing.assert_allclose(angle_diff(after, before + offset), 0, atol=1e-9)


def test_horizon_at_shifts_every_elevation_alike() -> None:
    raw = RAW.horizon_at(160.0)
    assert float(raw.radius_to_elevation(160.0)) == pytest.approx(0.0, abs=1e-12)
    assert np.diff(raw.elevations) == pytest.approx(np.diff(RAW.elevations))
    pano = PANORAMA.horizon_at(40.25)
    assert pano.horizon_row == pytest.approx(40.25)
    assert pano.row_step == pytest.approx(PANORAMA.row_step)


def test_other_direction() -> None:
    assert other_direction("ccw") == "cw" and other_direction("cw") == "ccw"
    with pytest.raises(ValueError, match="direction"):
        other_direction("up")  # type: ignore[arg-type]
