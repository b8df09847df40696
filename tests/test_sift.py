"""The sift method end to end on features and images whose truth the test controls.

``home`` runs on hand-built features (landmarks at one distance from the goal, their pixels from
the camera model, one random descriptor per landmark), so the answer must be exact (1e-6 rad)
with elimination on (P) or off (PN); injected mismatches must be removed by P. ``describe`` runs
on textured images: the bearings and sides it stores must be geometry.py's.
"""

from __future__ import annotations

import math
import pickle

import cv2
import numpy as np
import pytest

from homebench.data.synth.spec import WorldSpec
from homebench.errors import ConfigError
from homebench.geometry import (
    PanoramaGeometry,
    Pose,
    angular_error,
    home_direction,
)
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.sift.method import Sift, SiftFeatures, SiftUnfolded, panorama_sides

RAW = WorldSpec().raw.geometry()  # the Bielefeld-format raw camera
GOAL = Pose(0.2, 0.1, -0.6)
CAMERA_HEIGHT = 1.0
EXACT = 1e-6
P = Sift()
PN = Sift(horizon_constraint=False, half_plane_constraint=False)


def _world(n: int = 60, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Landmarks (n, 3) 3 m from the goal (horizontally), and one descriptor each (n, 128)."""
    rng = np.random.default_rng(seed)
    direction = rng.uniform(-math.pi, math.pi, n)
    height = rng.uniform(0.2, 2.2, n)  # below and above the camera (1 m)
    landmarks = np.column_stack(
        [GOAL.x + 3.0 * np.cos(direction), GOAL.y + 3.0 * np.sin(direction), height]
    )
    descriptors = rng.uniform(0.0, 100.0, (n, 128)).astype(np.float32)
    return landmarks, descriptors


def _features(landmarks: np.ndarray, descriptors: np.ndarray, pose: Pose) -> SiftFeatures:
    """What describe would return for exactly located landmarks (exact float64 azimuths)."""
    azimuth, elevation = pose.bearing_to(landmarks, CAMERA_HEIGHT)
    u, v = RAW.bearing_to_pixel(azimuth, elevation)
    return SiftFeatures(
        positions=np.column_stack([u, v]).astype(np.float32),
        descriptors=descriptors,
        azimuths=azimuth,
        sides=RAW.horizon_side(u, v, P.horizon_tolerance_px),
    )


def test_registered_with_the_papers_defaults():
    method = registry.create("sift")
    assert isinstance(method, Sift) and method.image_kind == "raw"
    assert (method.n_octave_layers, method.contrast_threshold) == (5, 0.04)  # T_DoG = 0.04 / S
    assert (method.n_references, method.vote_threshold) == (5, 4)
    assert isinstance(registry.create("sift-unfolded"), SiftUnfolded)
    assert registry.create("sift-unfolded").image_kind == "unfolded"


@pytest.mark.parametrize(
    "params", [{"ratio": 1.5}, {"vote_threshold": 6}, {"max_triples": 0}, {"n_octave_layers": 0}]
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError, match="sift"):
        registry.create("sift", **params)


@pytest.mark.parametrize("method", [P, PN], ids=["P", "PN"])
@pytest.mark.parametrize("offset", [(0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)])
@pytest.mark.parametrize("heading", [-0.6, 1.9])  # the goal's heading, and a turned robot
def test_home_is_exact_on_exact_landmarks(method, offset, heading):
    landmarks, descriptors = _world()
    current = Pose(GOAL.x + offset[0], GOAL.y + offset[1], heading)
    goal_features = _features(landmarks, descriptors, GOAL)
    estimate = method.home(_features(landmarks, descriptors, current), goal_features)
    assert estimate.angle is not None
    assert angular_error(estimate.angle, home_direction(current.xy, GOAL.xy, heading)) < EXACT
    assert angular_error(estimate.rotation, heading - GOAL.heading) < EXACT
    assert estimate.n_landmarks >= 3 and estimate.diagnostics["n_matches"] == len(landmarks)


def test_elimination_removes_injected_mismatches():
    landmarks, descriptors = _world(n=80, seed=1)
    current = Pose(GOAL.x - 0.4, GOAL.y + 0.3, 2.5)
    goal_features = _features(landmarks, descriptors, GOAL)
    azimuth, elevation = GOAL.bearing_to(landmarks, CAMERA_HEIGHT)
    above, below = np.flatnonzero(elevation > 0.1), np.flatnonzero(elevation < -0.1)
    # Swap the descriptors of landmarks across the horizon (constraint 1's case) and of
    # landmarks on the same side but about half a turn apart (constraint 2's case).
    swaps = [(above[0], below[0]), (above[1], below[1])]
    others = below[3:]
    far = others[np.argmin(np.cos(azimuth[others] - azimuth[below[2]]))]
    swaps.append((below[2], far))
    mixed = descriptors.copy()
    for i, j in swaps:
        mixed[[i, j]] = mixed[[j, i]]
    current_features = _features(landmarks, mixed, current)
    truth = home_direction(current.xy, GOAL.xy, current.heading)

    p = P.home(current_features, goal_features)
    assert angular_error(p.angle, truth) < EXACT
    assert p.diagnostics["n_after_horizon"] == len(landmarks) - 4
    assert p.diagnostics["n_after_half_plane"] <= len(landmarks) - 6
    pn = PN.home(current_features, goal_features)
    assert angular_error(pn.angle, truth) > 1e-3  # the mismatches did harm without elimination


def _doubled_goal() -> tuple[SiftFeatures, SiftFeatures]:
    """A goal whose 20 landmarks each appear twice (OpenCV's second orientation: same place,
    another descriptor), and a current view of the 20."""
    landmarks, descriptors = _world(n=20, seed=2)
    goal_features = _features(landmarks, descriptors, GOAL)
    doubled = SiftFeatures(
        positions=np.vstack([goal_features.positions] * 2),
        descriptors=np.vstack([descriptors, descriptors + 1.0]),
        azimuths=np.concatenate([goal_features.azimuths] * 2),
        sides=np.concatenate([goal_features.sides] * 2),
    )
    return _features(landmarks, descriptors, Pose(GOAL.x + 0.3, GOAL.y, 0.0)), doubled


def test_duplicate_keypoints_count_twice_as_in_the_paper():
    current, doubled = _doubled_goal()
    estimate = PN.home(current, doubled)
    assert estimate.diagnostics["n_matches"] == 40
    truth = home_direction(np.array([GOAL.x + 0.3, GOAL.y]), GOAL.xy, 0.0)
    assert angular_error(estimate.angle, truth) < EXACT  # a duplicate pair is still true


def test_distinct_matches_counts_duplicate_keypoints_once():
    current, doubled = _doubled_goal()
    method = Sift(horizon_constraint=False, half_plane_constraint=False, distinct_matches=True)
    assert method.home(current, doubled).diagnostics["n_matches"] == 20


@pytest.mark.parametrize("method", [P, PN], ids=["P", "PN"])
def test_identical_views_give_a_rotation_without_direction(method):
    landmarks, descriptors = _world()
    features = _features(landmarks, descriptors, GOAL)
    estimate = method.home(features, features)
    assert estimate.angle is None
    assert estimate.rotation == pytest.approx(0.0, abs=EXACT)
    assert estimate.diagnostics["n_direction_triples"] == 0


def test_the_ahead_filter_removes_triples_the_paper_keeps():
    landmarks, descriptors = _world(n=40, seed=6)
    current = Pose(GOAL.x - 0.4, GOAL.y + 0.3, 2.5)
    mixed = descriptors.copy()
    mixed[[0, 20]] = mixed[[20, 0]]  # one mismatch: some triples with it put a landmark behind
    args = (_features(landmarks, mixed, current), _features(landmarks, descriptors, GOAL))
    kept = PN.home(*args).diagnostics
    filtered = (
        Sift(horizon_constraint=False, half_plane_constraint=False, ahead_filter=True)
        .home(*args)
        .diagnostics
    )
    assert kept["n_valid_triples"] == kept["n_triples"]
    assert filtered["n_valid_triples"] < kept["n_valid_triples"]


def test_null_max_triples_solves_every_triple():
    landmarks, descriptors = _world(n=30, seed=7)
    current = _features(landmarks, descriptors, Pose(GOAL.x + 0.3, GOAL.y, 0.0))
    goal = _features(landmarks, descriptors, GOAL)
    assert Sift(max_triples=None).home(current, goal).diagnostics["n_triples"] == 4060
    assert P.home(current, goal).diagnostics["n_triples"] == 2000


def test_too_few_landmarks_give_no_estimate():
    landmarks, descriptors = _world(n=2, seed=3)
    goal_features = _features(landmarks, descriptors, GOAL)
    current = _features(landmarks, descriptors, Pose(GOAL.x + 0.3, GOAL.y, 0.0))
    for method in (P, PN):
        estimate = method.home(current, goal_features)
        assert estimate.angle is None and estimate.rotation is None
        assert estimate.diagnostics["reason"] == "fewer than 3 landmarks"


def _texture(shape: tuple[int, int], seed: int) -> np.ndarray:
    """A blotchy grey image with blobs at many scales (plenty of SIFT keypoints)."""
    rng = np.random.default_rng(seed)
    image = np.zeros(shape, dtype=np.float32)
    for sigma in (2.0, 5.0):
        image += cv2.GaussianBlur(rng.normal(0.0, 1.0, shape).astype(np.float32), (0, 0), sigma)
    image = (image - image.min()) / np.ptp(image) * 255.0
    return image.astype(np.uint8)


def test_describe_raw_keeps_geometry_bearings_and_sides():
    view = View(_texture((RAW.height, RAW.width), seed=4), RAW)
    features = P.describe(view)
    n = len(features)
    assert n > 100
    assert features.positions.shape == (n, 2) and features.positions.dtype == np.float32
    assert features.descriptors.shape == (n, 128) and features.descriptors.dtype == np.float32
    u, v = features.positions[:, 0], features.positions[:, 1]
    np.testing.assert_allclose(features.azimuths, RAW.pixel_to_bearing(u, v)[0])
    np.testing.assert_array_equal(features.sides, RAW.horizon_side(u, v, P.horizon_tolerance_px))
    assert {-1, 1} <= set(features.sides.tolist())
    radius = np.hypot(u - RAW.centre[0], v - RAW.centre[1])
    assert radius.min() >= RAW.inner_radius - 1 and radius.max() <= RAW.outer_radius + 1
    unmasked = Sift(mask_annulus=False).describe(view)
    unmasked_radius = np.hypot(*(unmasked.positions - np.array(RAW.centre, np.float32)).T)
    assert unmasked_radius.max() > RAW.outer_radius + 20
    again = pickle.loads(pickle.dumps(features))
    np.testing.assert_array_equal(again.descriptors, features.descriptors)
    assert P.describe(view).positions.tobytes() == features.positions.tobytes()  # deterministic


def test_describe_blank_image_gives_no_features_and_no_estimate():
    features = P.describe(View(np.full((RAW.height, RAW.width), 128, np.uint8), RAW))
    assert len(features) == 0 and features.descriptors.shape == (0, 128)
    estimate = P.home(features, features)
    assert estimate.angle is None and estimate.n_landmarks == 0


def test_describe_unfolded_wraps_the_seam():
    pano = PanoramaGeometry(width=720, height=190, elevation_top=0.8, elevation_bottom=-0.85)
    image = _texture((pano.height, pano.width), seed=5)
    method = SiftUnfolded()
    features = method.describe(View(image, pano))
    assert features.period == 720.0
    u = features.positions[:, 0]
    assert u.min() >= 0.0 and u.max() < 720.0
    np.testing.assert_allclose(features.azimuths, pano.column_to_azimuth(u))
    # Rolling the panorama by half a turn moves the seam: the same places are found again.
    rolled = method.describe(View(np.roll(image, 360, axis=1), pano))
    assert abs(len(rolled) - len(features)) < 0.05 * len(features)
    near_seam = (u < 8) | (u > 712)
    assert near_seam.sum() > 0


def test_panorama_sides_follow_elevation():
    pano = PanoramaGeometry(width=360, height=100, elevation_top=1.0, elevation_bottom=-1.0)
    horizon = pano.horizon_row  # 49.5: rows above it look up
    rows = np.array([0.0, horizon - 3.0, horizon - 0.5, horizon + 0.5, horizon + 3.0, 99.0])
    assert panorama_sides(pano, rows, 1.0).tolist() == [1, 1, 0, 0, -1, -1]
    assert panorama_sides(pano, rows, 0.0).tolist() == [1, 1, 1, -1, -1, -1]
