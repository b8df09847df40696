"""KLT tracking on panoramas: wrap-around, accuracy against the arena's exact geometry, the
forward-backward check, replenishment.

Ground truth: a corner seen at (column, row) from one pose is a point on the arena wall (the ray
meets the cylinder; its height follows from the row's elevation); projecting that point into the
other pose gives where the track must be. Pure turns are whole-column rolls, exact to the pixel.
"""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_panorama import (
    ARENA_RADIUS,
    CAMERA_HEIGHT,
    GEOMETRY,
    WALL_HEIGHT,
    render,
    rolled,
)

from homebench.errors import ConfigError
from homebench.geometry import Pose
from homebench.methods.klt_sector.tracking import (
    KltTracker,
    Tracks,
    circular_column_distance,
    column_shift,
)

POSE = Pose(0.1, 0.2, 0.3)


def reproject(positions: np.ndarray, source: Pose, target: Pose) -> np.ndarray:
    """Where wall points seen at ``positions`` (n, 2) from ``source`` appear from ``target``."""
    azimuth = GEOMETRY.column_to_azimuth(positions[:, 0])
    elevation = GEOMETRY.row_to_elevation(positions[:, 1])
    ux, uy = np.cos(source.heading + azimuth), np.sin(source.heading + azimuth)
    along = source.x * ux + source.y * uy
    distance = -along + np.sqrt(along**2 - (source.x**2 + source.y**2) + ARENA_RADIUS**2)
    z = np.clip(CAMERA_HEIGHT + distance * np.tan(elevation), 0.0, WALL_HEIGHT)
    points = np.stack([source.x + distance * ux, source.y + distance * uy, z], axis=-1)
    az, el = target.bearing_to(points, CAMERA_HEIGHT)
    return np.stack([GEOMETRY.azimuth_to_column(az), GEOMETRY.elevation_to_row(el)], axis=-1)


@pytest.fixture(scope="module")
def start() -> tuple[np.ndarray, Tracks]:
    image = render(POSE).image
    return image, Tracks.start(KltTracker().detect(image))


@pytest.mark.parametrize("shift", [0, 1, 37, -60, 143, -144])
def test_column_shift_finds_the_roll(start, shift):
    image, _ = start
    assert column_shift(image, np.roll(image, shift, axis=1)) == ((shift + 144) % 288) - 144


def test_detect_gives_separated_corners_on_the_whole_turn(start):
    image, tracks = start
    corners = tracks.positions
    assert len(corners) >= 50
    assert np.all((corners[:, 0] >= 0) & (corners[:, 0] < GEOMETRY.width))
    distance = circular_column_distance(corners[:, None], corners[None], GEOMETRY.width)
    np.fill_diagonal(distance, np.inf)
    assert distance.min() >= KltTracker().min_distance


def test_detect_is_unchanged_by_a_roll_across_column_zero(start):
    """Corners near the seam are found as well as anywhere (the image is padded circularly)."""
    image, tracks = start
    shift = 150
    moved = KltTracker().detect(np.roll(image, shift, axis=1))
    expected = tracks.positions + np.float32([shift, 0])
    expected[:, 0] %= GEOMETRY.width
    distance = circular_column_distance(moved[:, None], expected[None], GEOMETRY.width)
    assert len(moved) == len(expected)
    assert np.all(distance.min(axis=1) < 1e-3)


def test_detect_keeps_away_from_existing_corners(start):
    image, tracks = start
    existing = tracks.positions[::2]
    extra = KltTracker().detect(image, existing)
    distance = circular_column_distance(extra[:, None], existing[None], GEOMETRY.width)
    assert len(extra) > 0 and distance.min() >= KltTracker().min_distance


@pytest.mark.parametrize("shift", [37, -53])
def test_a_turn_across_column_zero_loses_no_track(start, shift):
    image, tracks = start
    tracker = KltTracker(prealign=True)  # tens of columns at once: a no-compass test's turn
    result = tracker.step(image, tracks, np.roll(image, shift, axis=1), replenish=False)
    expected = tracks.positions + np.float32([shift, 0])
    crossed = (expected[:, 0] < 0) | (expected[:, 0] >= GEOMETRY.width)
    expected[:, 0] %= GEOMETRY.width
    assert crossed.sum() >= 5
    assert result.alive.all()
    np.testing.assert_array_equal(result.ids, tracks.ids)
    assert circular_column_distance(result.positions, expected, GEOMETRY.width).max() < 0.05


def test_without_prealignment_as_in_the_paper_a_big_turn_is_not_followed(start):
    """The paper tracks at frame rate and needs no prealignment; a 37-column turn in one step
    is beyond the LK pyramid: tracks are lost or land elsewhere (what prealign is for)."""
    image, tracks = start
    result = KltTracker().step(image, tracks, np.roll(image, 37, axis=1), replenish=False)
    expected = tracks.positions + np.float32([37, 0])
    expected[:, 0] %= GEOMETRY.width
    error = circular_column_distance(result.positions, expected, GEOMETRY.width)
    assert np.mean(result.alive & (error < 0.05)) < 0.5


def test_tracks_follow_a_small_motion_with_a_turn(start):
    image, tracks = start
    turn = 25 * GEOMETRY.column_step  # features cross column 0
    target = Pose(POSE.x + 0.06, POSE.y - 0.04, POSE.heading + turn)
    tracker = KltTracker(prealign=True)
    result = tracker.step(image, tracks, render(target).image, replenish=False)
    expected = reproject(tracks.positions, POSE, target)
    error = circular_column_distance(result.positions, expected, GEOMETRY.width)[result.alive]
    crossed = np.abs(result.positions[:, 0] - tracks.positions[:, 0]) > GEOMETRY.width / 2
    assert result.alive.mean() >= 0.9
    assert np.count_nonzero(crossed & result.alive) >= 3
    assert np.median(error) < 0.3
    assert np.percentile(error, 95) < 1.0


def test_forward_backward_check_drops_a_feature_whose_patch_changed(start):
    image, tracks = start
    k = int(np.argmin(np.hypot(tracks.positions[:, 0] - 144, tracks.positions[:, 1] - 20)))
    u, v = np.rint(tracks.positions[k]).astype(int)
    changed = image.copy()
    half = 12  # the LK window (21 x 21) and a little more
    noise = np.random.default_rng(0).integers(0, 256, (2 * half + 1, 2 * half + 1))
    changed[v - half : v + half + 1, u - half : u + half + 1] = noise
    result = KltTracker(fb_threshold=1.0).step(image, tracks, changed, replenish=False)
    far = circular_column_distance(tracks.positions, tracks.positions[k], GEOMETRY.width) > 40
    assert not result.alive[k]
    assert result.alive[far].all()
    np.testing.assert_array_equal(result.positions[k], tracks.positions[k])  # last position
    assert k not in result.survivors().ids
    # Without the check (the paper's life-cycle), KLT keeps the feature, somewhere else.
    unchecked = KltTracker().step(image, tracks, changed, replenish=False)
    assert unchecked.alive[k]
    assert np.hypot(*(unchecked.positions[k] - tracks.positions[k])) > 2.0


def test_replenishing_adds_new_ids_away_from_the_survivors(start):
    image, tracks = start
    few = Tracks.start(tracks.positions[:5])
    target = rolled(render(POSE), 3).image
    result = KltTracker(min_tracks=50).step(image, few, target)
    born = result.ids >= few.next_id
    assert result.alive.all() and born.sum() >= 45
    np.testing.assert_array_equal(result.ids[:5], few.ids)
    assert result.next_id == few.next_id + born.sum()
    distance = circular_column_distance(
        result.positions[born][:, None], result.positions[~born][None], GEOMETRY.width
    )
    assert distance.min() >= KltTracker().min_distance
    assert len(KltTracker(min_tracks=50).step(image, few, target, replenish=False)) == 5


def test_tracking_along_a_route_keeps_most_tracks(start):
    image, tracks = start
    tracker = KltTracker()
    poses = [Pose(POSE.x + 0.05 * k, POSE.y, POSE.heading + 0.05 * k) for k in range(1, 11)]
    previous = image
    for pose in poses:
        following = render(pose).image
        tracks = tracker.step(previous, tracks, following, replenish=False).survivors()
        previous = following
    initial = Tracks.start(KltTracker().detect(image))
    origin = initial.positions[tracks.ids]
    error = circular_column_distance(tracks.positions, reproject(origin, POSE, poses[-1]), 288)
    assert len(tracks) >= 0.8 * len(initial)
    assert np.median(error) < 0.5


def test_bad_parameters_are_config_errors():
    with pytest.raises(ConfigError):
        KltTracker(quality_level=0.0)
    with pytest.raises(ConfigError):
        KltTracker(window_size=1)
    with pytest.raises(ConfigError):
        KltTracker(fb_threshold=0.0)


def test_pad_covers_the_coarsest_window():
    tracker = KltTracker(window_size=21, pyramid_levels=3)
    assert tracker.pad_width(1000) == 88
    assert tracker.pad_width(50) == 50
