"""The camera mount's tilt: rotation, draws, resampling, and bearings in tilted views against
ground truth."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from marker_box import face_centres, with_marker

from homebench.data.synth.camera import CameraSpec
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.tilt import Tilt, level_geometry, tilted
from homebench.data.synth.world import World, build_world, position_noise_seed, render_position
from homebench.geometry import Pose

TILTED = WorldSpec(seed=2, camera=CameraSpec(tilt_deg=6.0))
SMALL = {"seed": 5, "grid": {"shape": (3, 4)}, "unfolded": {"width": 180}}
# a checkered box: each face shows an X corner at its centre (x, y, z in metres)


def test_the_tilt_leans_the_axis_towards_its_direction():
    tilt = Tilt(np.radians(5.0), np.radians(120.0))
    r = tilt.matrix()
    assert np.allclose(r @ r.T, np.eye(3)) and np.isclose(np.linalg.det(r), 1.0)
    axis = r @ [0.0, 0.0, 1.0]
    assert np.isclose(np.degrees(np.arccos(axis[2])), 5.0)
    assert np.isclose(np.degrees(np.arctan2(axis[1], axis[0])), 120.0)
    # the camera's horizon dips 5 deg on the side it leans to (it looks further down there)
    _, elevation = tilt.to_upright(np.radians(120.0), 0.0)
    assert np.isclose(np.degrees(elevation), -5.0)
    azimuth, elevation = np.meshgrid(np.linspace(-3, 3, 7), np.linspace(-1, 1, 5))
    back = tilt.to_camera(*tilt.to_upright(azimuth, elevation))
    assert np.allclose(back, (azimuth, elevation))


def test_draws_stay_within_the_bound_and_cover_every_direction():
    rng = np.random.default_rng(0)
    draws = [Tilt.draw(3.0, rng) for _ in range(4000)]
    angles = np.degrees([t.angle for t in draws])
    assert angles.max() <= 3.0 and np.isclose(angles.mean(), 2.0, atol=0.05)  # disc: 2/3 max
    directions = np.array([t.direction for t in draws])
    assert np.abs(np.mean(np.exp(1j * directions))) < 0.05


def test_a_zero_tilt_resamples_the_upright_panorama_exactly():
    world = build_world(WorldSpec(**SMALL))
    target = world.panorama_geometry
    source = level_geometry(target, 2.0)
    upright = world.panorama(WorldSpec(**SMALL).pose(1, 1), source)[0]
    margin = (source.height - target.height) // 2
    same = tilted(upright, source, target, Tilt(0.0, 1.0))
    assert np.allclose(same, upright[margin : margin + target.height], rtol=1e-5)


def test_zero_tilt_keeps_the_key_and_the_bytes():
    plain = WorldSpec(**SMALL)
    assert WorldSpec(**SMALL, camera={"tilt_deg": 0.0}).key() == plain.key()
    assert "tilt_deg" not in plain.canonical_json()
    spec = WorldSpec(**SMALL, camera={"tilt_deg": 3.0})
    assert spec.key() != plain.key()
    pose = plain.pose(1, 2)  # an upright capture of a tilting camera: the plain one's bytes
    upright, level = build_world(spec).render(pose, None), build_world(plain).render(pose, None)
    assert all(np.array_equal(upright[kind], level[kind]) for kind in level)
    tilted_images = render_position(spec, 1, 2)
    assert np.mean(tilted_images["unfolded"] != render_position(plain, 1, 2)["unfolded"]) > 0.3


def test_a_position_has_one_tilt_in_every_variant_and_the_ground_truth_says_it():
    spec = WorldSpec(**SMALL, camera={"tilt_deg": 3.0})
    seed = position_noise_seed(spec.seed, 2, 1)
    day = build_world(spec.model_copy(update={"variant": "day"}))
    assert build_world(spec).tilt(seed) == day.tilt(seed)
    truth = json.loads(json.dumps(build_world(spec).ground_truth()))["camera_tilts"]
    assert len(truth) == 12 and truth["2_1"] == build_world(spec).tilt(seed).degrees()
    assert all(0 <= t["angle_deg"] <= 3.0 for t in truth.values())
    assert "camera_tilts" not in build_world(WorldSpec(**SMALL)).ground_truth()


def test_landmark_images_refuse_a_tilt():
    with pytest.raises(ValueError, match="tilt_deg applies to photographs"):
        WorldSpec(render="landmarks", camera={"tilt_deg": 1.0})


@pytest.fixture(scope="module")
def marker_world() -> World:
    """The tilted world plus the checkered box (tests/marker_box.py)."""
    return with_marker(TILTED, TILTED.model_copy(update={"camera": CameraSpec()}))


def _visible_face_centres(pose: Pose) -> list[np.ndarray]:
    """3-D centres of the marker's faces seen from ``pose`` within 60 deg of their normal."""
    seen = []
    for centre, normal in face_centres():
        to_camera = pose.xy - centre[:2]
        if normal @ to_camera >= 0.5 * np.linalg.norm(to_camera):
            seen.append(centre)
    return seen


def _saddle(image: np.ndarray, x: float, y: float, win: int) -> np.ndarray:
    """The X corner found by cv2.cornerSubPix, started 1 px away from (x, y)."""
    start = np.array([[[x + 0.8, y - 0.6]]], np.float32)
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 0.001)
    return cv2.cornerSubPix(image.astype(np.float32), start, (win, win), (-1, -1), criteria)[0, 0]


@pytest.mark.parametrize(("pose", "seed"), [(Pose(2.2, 4.0, 0.0), 1), (Pose(3.8, 4.5, 2.5), 2)])
def test_tilted_views_show_a_corner_at_its_tilted_bearing(marker_world, pose, seed):
    """Measured: 0.01-0.07 px (unfolded) and 0.03-0.08 px (raw) from the tilted bearing,
    1-3 px from the upright one, for tilts of 4-5.5 deg."""
    tilt = marker_world.tilt(seed)
    assert np.degrees(tilt.angle) > 3.0
    images = marker_world.render(pose, seed)
    unfolded, raw = marker_world.unfolded_geometry, marker_world.raw_geometry
    centres = _visible_face_centres(pose)
    assert centres
    for point in centres:
        upright = pose.bearing_to(point, TILTED.camera_height)
        az, el = tilt.to_camera(*upright)
        expected = np.array([unfolded.azimuth_to_column(az), unfolded.elevation_to_row(el)])
        assert np.hypot(*(_saddle(images["unfolded"], *expected, 3) - expected)) < 0.2
        level = np.array(
            [unfolded.azimuth_to_column(upright[0]), unfolded.elevation_to_row(upright[1])]
        )
        assert np.hypot(*(expected - level)) > 1.0
        pixel = np.array(raw.bearing_to_pixel(az, el), dtype=float)
        assert np.hypot(*(_saddle(images["raw"], *pixel, 4) - pixel)) < 0.2
