"""Property-based tests (hypothesis) of the angle utilities and the run-config loader."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from homebench.config import RunConfig, load_config
from homebench.errors import ConfigError
from homebench.geometry import (
    CatadioptricGeometry,
    PanoramaGeometry,
    angle_diff,
    angular_error,
    robot_to_world,
    world_to_robot,
    wrap_angle,
)

# Shared CI machines are noisy: no per-example deadline (the properties, not speed, are tested).
settings.register_profile("homebench", deadline=None, derandomize=True)
settings.load_profile("homebench")

angles = st.floats(-1e4, 1e4, allow_nan=False)


@given(angles)
def test_wrap_is_in_range_idempotent_and_same_direction(a: float) -> None:
    w = float(wrap_angle(a))
    assert -math.pi <= w < math.pi
    assert float(wrap_angle(w)) == w
    assert math.isclose(math.cos(w), math.cos(a), abs_tol=1e-9)
    assert math.isclose(math.sin(w), math.sin(a), abs_tol=1e-9)


@given(angles, angles)
def test_error_is_symmetric_bounded_and_consistent_with_diff(a: float, b: float) -> None:
    e = float(angular_error(a, b))
    assert 0.0 <= e <= math.pi
    assert math.isclose(e, float(angular_error(b, a)), abs_tol=1e-9)
    assert math.isclose(e, abs(float(angle_diff(a, b))), abs_tol=1e-12)


@given(angles, angles)
def test_robot_world_round_trip(azimuth: float, heading: float) -> None:
    back = world_to_robot(robot_to_world(azimuth, heading), heading)
    assert float(angular_error(back, azimuth)) < 1e-9


@given(
    st.integers(16, 1440),
    st.sampled_from(["ccw", "cw"]),
    st.floats(0, 1000, allow_nan=False),
    angles,
)
def test_panorama_azimuth_column_round_trip(width, direction, zero, azimuth) -> None:
    g = PanoramaGeometry(width, 10, 0.5, -0.5, direction, zero_column=zero % width)
    column = float(g.azimuth_to_column(azimuth))
    assert 0.0 <= column < width
    assert float(angular_error(g.column_to_azimuth(column), azimuth)) < 1e-9


@given(
    st.sampled_from(["ccw", "cw"]),
    st.floats(-math.pi, math.pi),
    angles,
    st.floats(-0.8, 0.7),
)
def test_catadioptric_bearing_pixel_round_trip(direction, zero, azimuth, elevation) -> None:
    g = CatadioptricGeometry(
        752, 564, (375.5, 281.5), (25.0, 150.0, 270.0), (-0.87, 0.0, 0.79), direction, zero
    )
    u, v = g.bearing_to_pixel(azimuth, elevation)
    az, el = g.pixel_to_bearing(u, v)
    assert float(angular_error(az, azimuth)) < 1e-9
    assert math.isclose(float(el), elevation, abs_tol=1e-9)


# ----------------------------------------------------------------------------- config loader

json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-5, 5)
    | st.floats(allow_nan=False)
    | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=8,
)
KEYS = sorted(RunConfig.model_fields)
BASE = {
    "output": "runs/x",
    "databases": {"a": "synth-original"},
    "conditions": ["a-a"],
    "goals": [[1, 1]],
    "methods": [{"method": "warping"}],
}


@settings(max_examples=150, deadline=None)
@given(st.dictionaries(st.sampled_from([*KEYS, "typo", "jobz"]), json_values, max_size=4))
def test_config_loader_accepts_or_names_the_problem(tmp_path_factory, changes: dict) -> None:
    """Any YAML document either loads or gives a ConfigError naming the file — never a crash."""
    path = Path(tmp_path_factory.mktemp("cfg")) / "config.yaml"
    path.write_text(yaml.safe_dump({**BASE, **changes}))
    try:
        config = load_config(path)
    except ConfigError as error:
        assert str(path) in str(error)
    else:
        assert isinstance(config, RunConfig)
        assert np.all([m.method for m in config.methods])
