"""Seed 001's triple solver and circular least squares against exact synthetic bearings.

Bearings come from :meth:`Pose.bearing_to` (geometry.py's conventions): landmarks at one distance
from the goal satisfy eq. 3 exactly, so every triple must give the true (rho, psi, alpha) and the
true home direction to 1e-6 rad. Displacements along +x, -x, +y, -y with turned headings catch a
mirrored axis or a flipped sign, which passes on one axis only.
"""

from __future__ import annotations

import math
from itertools import combinations
from math import comb

import numpy as np
import pytest

from homebench.geometry import (
    Pose,
    angle_diff,
    angular_error,
    home_direction,
    world_direction,
)
from homebench.methods.sift.solver import (
    choose_triples,
    circular_least_squares,
    estimate_movement,
    solve_triples,
)

GOAL = Pose(0.3, -0.2, 0.7)
EXACT = 1e-6


def _landmarks(centre: Pose, distances: np.ndarray, seed: int) -> np.ndarray:
    """Landmarks (n, 3) at the given horizontal distances from ``centre``, random directions."""
    rng = np.random.default_rng(seed)
    direction = rng.uniform(-math.pi, math.pi, len(distances))
    height = rng.uniform(-1.0, 1.5, len(distances))
    return np.stack(
        [
            centre.x + distances * np.cos(direction),
            centre.y + distances * np.sin(direction),
            height,
        ],
        axis=1,
    )


def _bearings(landmarks: np.ndarray, current: Pose) -> tuple[np.ndarray, np.ndarray]:
    return GOAL.bearing_to(landmarks)[0], current.bearing_to(landmarks)[0]


OFFSETS = [(0.4, 0.0), (-0.4, 0.0), (0.0, 0.4), (0.0, -0.4), (0.9, -0.7)]
HEADINGS = [0.7, -2.5, 2.9]  # 0.7 = the goal's heading (no turn); the others turn the robot


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("heading", HEADINGS)
def test_equal_distance_triples_recover_rho_psi_alpha(offset, heading):
    r = 3.0
    landmarks = _landmarks(GOAL, np.full(12, r), seed=1)
    current = Pose(GOAL.x + offset[0], GOAL.y + offset[1], heading)
    theta, theta_p = _bearings(landmarks, current)
    triples = np.array(list(combinations(range(12), 3)))
    solutions = solve_triples(theta, theta_p, triples)
    assert solutions.valid.all()
    np.testing.assert_allclose(solutions.rho, math.hypot(*offset) / r, atol=EXACT)
    alpha = world_direction(GOAL.xy, current.xy) - GOAL.heading
    assert np.max(angular_error(solutions.alpha, alpha)) < EXACT
    assert np.max(angular_error(solutions.psi, heading - GOAL.heading)) < EXACT


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("heading", HEADINGS)
def test_home_direction_and_rotation_are_exact(offset, heading):
    landmarks = _landmarks(GOAL, np.full(30, 2.5), seed=2)
    current = Pose(GOAL.x + offset[0], GOAL.y + offset[1], heading)
    movement = estimate_movement(*_bearings(landmarks, current), max_triples=500, seed=0)
    assert movement is not None
    assert movement.n_triples == 500 and movement.n_valid == 500
    truth = home_direction(current.xy, GOAL.xy, heading)
    assert angular_error(movement.home_direction, truth) < EXACT
    assert angular_error(movement.psi, heading - GOAL.heading) < EXACT
    assert movement.alpha_rms < EXACT


def test_the_root_with_landmarks_behind_the_robot_is_not_taken():
    # psi0 and psi0 + pi solve the equations alike; only one puts the landmarks ahead.
    landmarks = _landmarks(GOAL, np.full(3, 2.0), seed=3)
    for heading in np.linspace(-3.1, 3.1, 13):
        current = Pose(GOAL.x - 0.5, GOAL.y + 0.2, heading)
        theta, theta_p = _bearings(landmarks, current)
        solution = solve_triples(theta, theta_p, np.array([[0, 1, 2]]))
        assert solution.valid[0]
        assert angular_error(solution.psi[0], heading - GOAL.heading) < EXACT


def _degenerate_and_mismatched() -> tuple[np.ndarray, np.ndarray]:
    theta = np.array(
        [
            [0.1, 0.1, 1.0],  # two landmarks on one ray from both places
            [0.0, 2.0, -2.0],  # a valid triple (pure rotation by 0.3 below)
            [0.0, 2.0, -2.0],  # the same bearings, one of them mismatched (see theta_p)
        ]
    )
    theta_p = theta - 0.3
    theta_p[2, 1] = theta[2, 1] + math.pi - 0.3  # seen behind: no landmark ahead on all rays
    return theta.ravel(), theta_p.ravel()


def test_degenerate_triples_are_discarded_and_the_paper_keeps_the_rest():
    solutions = solve_triples(*_degenerate_and_mismatched(), np.arange(9).reshape(3, 3))
    assert solutions.valid.tolist() == [False, True, True]  # eq. 3 has a real solution
    assert solutions.rho[1] == pytest.approx(0.0, abs=EXACT)
    assert solutions.psi[1] == pytest.approx(0.3, abs=EXACT)


def test_the_ahead_filter_discards_triples_that_put_a_landmark_behind_the_robot():
    triples = np.arange(9).reshape(3, 3)
    solutions = solve_triples(*_degenerate_and_mismatched(), triples, ahead_filter=True)
    assert solutions.valid.tolist() == [False, True, False]


def test_identical_bearings_give_no_direction_and_no_turn():
    """rho = 0 in every triple: eq. 3 holds for any alpha, so there is no home direction."""
    theta = GOAL.bearing_to(_landmarks(GOAL, np.full(20, 2.0), seed=10))[0]
    movement = estimate_movement(theta, theta, max_triples=500, seed=0)
    assert movement is not None
    assert movement.alpha is None and movement.home_direction is None
    assert movement.psi == pytest.approx(0.0, abs=EXACT)
    assert movement.n_valid == movement.n_triples and movement.n_direction == 0


def test_a_turn_on_the_spot_gives_the_turn_without_a_direction():
    theta = GOAL.bearing_to(_landmarks(GOAL, np.full(20, 2.0), seed=11))[0]
    movement = estimate_movement(theta, theta - 0.7, max_triples=500, seed=0)
    assert movement.home_direction is None
    assert angular_error(movement.psi, 0.7) < EXACT


def test_too_few_landmarks_or_no_solution_gives_none():
    assert estimate_movement(np.array([0.1, 1.0]), np.array([0.2, 1.1]), 100, 0) is None
    same_ray = np.array([0.5, 0.5, 0.5, 0.5])
    assert estimate_movement(same_ray, same_ray, 100, 0) is None


def test_unequal_distances_still_bring_the_robot_home():
    """Franz et al. (1998): the equal-distance assumption biases the home direction, but the
    bias stays well below 90 deg, so the robot approaches the goal with arbitrary accuracy.

    (The angular error itself does not vanish near the goal: with exact bearings the linearised
    equations are scale-free in d, so it tends to a constant set by the landmark layout.)
    """
    landmarks = _landmarks(GOAL, np.random.default_rng(4).uniform(1.5, 5.0, 40), seed=5)
    theta = GOAL.bearing_to(landmarks)[0]
    rng = np.random.default_rng(6)
    step = 0.05
    position = GOAL.xy + np.array([1.2, -0.9])
    distances = [float(np.hypot(*(position - GOAL.xy)))]
    for _ in range(60):
        heading = float(rng.uniform(-math.pi, math.pi))
        current = Pose(float(position[0]), float(position[1]), heading)
        movement = estimate_movement(theta, current.bearing_to(landmarks)[0], 2000, 0)
        error = angular_error(movement.home_direction, home_direction(position, GOAL.xy, heading))
        assert error < math.radians(45)
        world = heading + movement.home_direction
        position = position + step * np.array([math.cos(world), math.sin(world)])
        distances.append(float(np.hypot(*(position - GOAL.xy))))
    far = [b - a for a, b in zip(distances, distances[1:], strict=False) if a > step]
    assert all(change < 0 for change in far)  # every step outside one step's reach gets nearer
    assert min(distances) < step


def test_circular_least_squares_is_the_exact_minimiser():
    rng = np.random.default_rng(7)
    grid = np.linspace(-math.pi, math.pi, 200001)
    for angles in (
        rng.normal(math.pi, 0.3, 50),  # clustered across the -pi / pi seam
        rng.uniform(-math.pi, math.pi, 40),
        np.concatenate([rng.normal(1.0, 0.1, 30), rng.normal(-2.5, 0.4, 25)]),
    ):
        mean, ssd = circular_least_squares(angles)
        brute = np.sum(angle_diff(angles[:, None], grid[None, :]) ** 2, axis=0)
        assert ssd == pytest.approx(float(np.sum(angle_diff(angles, mean) ** 2)), rel=1e-9)
        assert ssd <= brute.min() + 1e-9
        assert angular_error(mean, grid[np.argmin(brute)]) < 1e-3


def test_circular_least_squares_of_equal_angles():
    mean, ssd = circular_least_squares(np.full(7, -3.0))
    assert mean == pytest.approx(-3.0) and ssd == pytest.approx(0.0, abs=1e-9)


def test_all_triples_when_few_a_seeded_sample_when_many():
    every = choose_triples(7, 35, np.random.default_rng(0))
    assert [tuple(t) for t in every] == list(combinations(range(7), 3))
    sample = choose_triples(40, 3000, np.random.default_rng(1))
    assert sample.shape == (3000, 3)
    assert sample.min() == 0 and sample.max() == 39
    assert np.all((sample[:, 0] != sample[:, 1]) & (sample[:, 0] != sample[:, 2]))
    assert np.all(sample[:, 1] != sample[:, 2])
    counts = np.bincount(sample.ravel(), minlength=40)
    assert counts.min() > 0.5 * counts.mean()  # no index left out or starved
    again = choose_triples(40, 3000, np.random.default_rng(1))
    np.testing.assert_array_equal(sample, again)
    assert choose_triples(2, 10, np.random.default_rng(0)).shape == (0, 3)


def test_no_limit_solves_every_triple():
    every = choose_triples(30, None, np.random.default_rng(0))
    assert [tuple(t) for t in every] == list(combinations(range(30), 3))
    bearings = _bearings(_landmarks(GOAL, np.full(30, 2.5), seed=12), Pose(0.9, 0.1, 2.0))
    assert estimate_movement(*bearings, max_triples=None, seed=0).n_triples == comb(30, 3)


def test_sampled_estimates_are_deterministic():
    landmarks = _landmarks(GOAL, np.random.default_rng(8).uniform(1.5, 5.0, 60), seed=9)
    current = Pose(GOAL.x + 0.6, GOAL.y, -1.0)
    bearings = _bearings(landmarks, current)
    first = estimate_movement(*bearings, max_triples=300, seed=3)
    assert first == estimate_movement(*bearings, max_triples=300, seed=3)
    assert first != estimate_movement(*bearings, max_triples=300, seed=4)
