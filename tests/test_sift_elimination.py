"""Seed 001's mismatch elimination: constraint 1 (horizon circle) and 2 (half-plane votes).

Each constraint is tested on its own with hand-made pairs, on a raw camera model like the
Bielefeld one (752 x 564, mirror seen from below: azimuth grows clockwise on screen).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.data.synth.spec import WorldSpec
from homebench.geometry import Pose
from homebench.methods.sift.elimination import (
    half_plane_constraint,
    half_plane_votes,
    horizon_constraint,
    reference_landmarks,
)

RAW = WorldSpec().raw.geometry()  # the Bielefeld-format raw camera


def _pixels(azimuth_deg: float, elevation_deg: float) -> tuple[float, float]:
    u, v = RAW.bearing_to_pixel(math.radians(azimuth_deg), math.radians(elevation_deg))
    return float(u), float(v)


def test_constraint_1_on_hand_made_sides():
    goal = np.array([1, -1, 0, 1, -1, 0], dtype=np.int8)
    current = np.array([1, -1, 0, -1, 1, 1], dtype=np.int8)
    assert horizon_constraint(goal, current).tolist() == [True, True, True, False, False, False]


def test_constraint_1_removes_pairs_across_the_horizon_circle():
    tolerance = 1.0
    # the elevation imaged half a pixel off the horizon circle, in degrees
    half_px = math.degrees(RAW.radius_to_elevation(RAW.horizon_radius + 0.5))
    pairs = [  # (goal pixel, current pixel) of one landmark, and whether the pair is kept
        ((30.0, 12.0), (50.0, 8.0), True),  # above in both images
        ((-100.0, -20.0), (-95.0, -31.0), True),  # below in both
        ((170.0, half_px), (160.0, -half_px), True),  # on the circle in both (within 1 px)
        ((10.0, 12.0), (15.0, -12.0), False),  # above -> below: a mismatch
        ((-60.0, -5.0), (-40.0, 25.0), False),  # below -> above: a mismatch
        ((90.0, 0.0), (85.0, 6.0), False),  # on the circle -> above: eq. 8 differs
    ]
    goal = np.array([_pixels(*g) for g, _, _ in pairs])
    current = np.array([_pixels(*c) for _, c, _ in pairs])
    side_goal = RAW.horizon_side(goal[:, 0], goal[:, 1], tolerance)
    side_current = RAW.horizon_side(current[:, 0], current[:, 1], tolerance)
    kept = horizon_constraint(side_goal, side_current)
    assert kept.tolist() == [keep for _, _, keep in pairs]


def test_reference_landmarks_are_the_nearest_others():
    positions = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [5.0, 5.0], [0.5, 0.1]])
    refs = reference_landmarks(positions, 2, period=0.0)
    assert [sorted(r) for r in refs.tolist()] == [[1, 4], [0, 4], [0, 4], [1, 2], [0, 1]]
    assert reference_landmarks(positions, 10, 0.0).shape == (5, 4)  # at most the others
    assert reference_landmarks(positions[:1], 5, 0.0).shape == (1, 0)


def test_reference_landmarks_wrap_around_a_panorama():
    positions = np.array([[1.0, 10.0], [358.0, 10.0], [40.0, 10.0]])
    assert reference_landmarks(positions, 1, period=360.0)[:, 0].tolist() == [1, 0, 0]
    assert reference_landmarks(positions, 1, period=0.0)[:, 0].tolist() == [2, 2, 0]


def test_votes_count_references_on_the_same_side_in_both_images():
    # Tested landmark 0 at azimuth 0; references on its left (+) or right (-) in the goal image.
    goal = np.radians([0.0, 30.0, 60.0, -30.0, -60.0, 100.0])
    current = np.radians([10.0, 50.0, 70.0, 5.0, -40.0, 200.0])
    # In the current image, seen from landmark 0 (10 deg): 50, 70 stay left; 5 and -40 stay
    # right; 200 moved to the right (sin(190 deg) < 0): 4 of 5 references agree.
    positions = np.column_stack([np.arange(6.0), np.zeros(6)])  # landmark 0's nearest: 1..5
    votes = half_plane_votes(positions, goal, current, n_references=5, period=0.0)
    assert votes[0] == 4


def test_votes_are_eq_9_on_pixels():
    """The azimuth test equals eq. 9-10 on raw pixels, with O the mirror's centre."""
    rng = np.random.default_rng(0)
    n = 40
    azimuth_goal, azimuth_current = rng.uniform(-math.pi, math.pi, (2, n))
    elevation = np.radians(rng.uniform(-40.0, 40.0, (2, n)))
    goal = np.column_stack(RAW.bearing_to_pixel(azimuth_goal, elevation[0]))
    current = np.column_stack(RAW.bearing_to_pixel(azimuth_current, elevation[1]))
    refs = reference_landmarks(goal, 5, 0.0)

    def gamma_lr(pixels: np.ndarray, tested: int, reference: int) -> int:
        (x_o, y_o), (x_t, y_t), (x_r, y_r) = RAW.centre, pixels[tested], pixels[reference]
        a, b, c = y_t - y_o, x_o - x_t, x_t * y_o - x_o * y_t
        return int(np.sign(a * x_r + b * y_r + c))

    expected = [
        sum(gamma_lr(goal, t, r) == gamma_lr(current, t, r) for r in refs[t]) for t in range(n)
    ]
    votes = half_plane_votes(goal, azimuth_goal, azimuth_current, 5, 0.0)
    assert votes.tolist() == expected


def test_constraint_2_removes_injected_mismatches_and_keeps_true_pairs():
    rng = np.random.default_rng(1)
    n = 80
    distance = rng.uniform(1.5, 4.0, n)
    direction = rng.uniform(-math.pi, math.pi, n)
    landmarks = np.column_stack(
        [distance * np.cos(direction), distance * np.sin(direction), rng.uniform(-1.0, 1.5, n)]
    )
    goal_pose, current_pose = Pose(0.0, 0.0, 0.3), Pose(0.25, -0.15, -0.8)
    azimuth_goal, elevation_goal = goal_pose.bearing_to(landmarks, camera_height=1.0)
    azimuth_current, _ = current_pose.bearing_to(landmarks, camera_height=1.0)
    positions = np.column_stack(RAW.bearing_to_pixel(azimuth_goal, elevation_goal))
    mismatched = np.array([3, 27, 51, 70])
    wrong = azimuth_current.copy()
    # Matched to a landmark on the far side of the room: every near reference changes side.
    wrong[mismatched] = azimuth_current[mismatched] + math.pi - 0.2
    kept = half_plane_constraint(positions, azimuth_goal, wrong, 5, 4, 0.0)
    assert not kept[mismatched].any()
    correct = np.setdiff1d(np.arange(n), mismatched)
    assert kept[correct].mean() > 0.9
    assert half_plane_constraint(positions, azimuth_goal, azimuth_current, 5, 4, 0.0).mean() > 0.9


@pytest.mark.parametrize("n", [1, 2, 4])
def test_constraint_2_cannot_confirm_pairs_with_too_few_references(n):
    azimuths = np.linspace(-1.0, 1.0, n)
    positions = np.column_stack([np.arange(n, dtype=float), np.zeros(n)])
    kept = half_plane_constraint(positions, azimuths, azimuths, 5, 4, 0.0)
    assert kept.tolist() == [False] * n
