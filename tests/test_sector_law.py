"""The sector law on exact bearings: its sign, its zero, the ordering filter, the median shift.

Landmarks are points on the floor plane around the goal; bearings are computed exactly with
:meth:`Pose.bearing_to`, so every expectation is ground truth we control.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from homebench.geometry import PanoramaGeometry, Pose, angle_diff, wrap_angle
from homebench.methods.klt_sector.sector_law import (
    bearings,
    goal_reached,
    heading_change,
    longest_common_order,
    longest_increasing,
    motion_vector,
    order_filter,
    sector_vectors,
)
from homebench.methods.klt_sector.sector_law_kernels import first_longest_rotation

GOAL = Pose(0.3, -0.2, 0.7)
COLUMN = 2.0 * math.pi / 288  # one column of a 288-column panorama


def landmarks(n: int, seed: int) -> np.ndarray:
    """n points (n, 3) 2-4 m from the goal, at random directions."""
    rng = np.random.default_rng(seed)
    angle, radius = rng.uniform(0, 2 * math.pi, n), rng.uniform(2.0, 4.0, n)
    return np.stack(
        [GOAL.x + radius * np.cos(angle), GOAL.y + radius * np.sin(angle), np.zeros(n)], axis=-1
    )


def law(current: Pose, points: np.ndarray, bisectors: str = "current") -> np.ndarray:
    """M at ``current`` (its robot frame) after the ordering filter, exact bearings."""
    theta_current = current.bearing_to(points)[0]
    theta_goal = GOAL.bearing_to(points)[0]
    kept = order_filter(theta_current, theta_goal)
    return motion_vector(theta_current[kept], theta_goal[kept], bisectors)


def test_bearings_are_eq_1():
    geometry = PanoramaGeometry(288, 48, 0.5, -0.5)
    x = np.array([0.0, 10.5, 143.0, 200.0, 287.9])
    np.testing.assert_allclose(bearings(x, geometry), wrap_angle(2 * np.pi * x / 288))


def test_a_sector_that_is_larger_at_the_goal_pulls_along_its_bisector():
    """Four landmarks on a square; the robot 0.5 m to the right of the goal must go left."""
    points = np.array([[2, 2, 0], [-2, 2, 0], [-2, -2, 0], [2, -2, 0]], dtype=float)
    goal, current = Pose(0, 0), Pose(0.5, 0)
    vectors = sector_vectors(current.bearing_to(points)[0], goal.bearing_to(points)[0])
    m = vectors.sum(axis=0)
    assert m[0] < 0 and abs(m[1]) < 1e-12
    # The left sector (between the two left landmarks) is larger at the goal: it pulls left.
    left = np.argmin(vectors[:, 0])
    assert vectors[left, 0] < 0 and abs(vectors[left, 1]) < 1e-12


@pytest.mark.parametrize("bisectors", ["current", "goal"])
@pytest.mark.parametrize(("n", "seed"), [(5, 1), (12, 2), (40, 3), (100, 4)])
def test_motion_vector_points_towards_the_goal_from_all_around(n, seed, bisectors):
    points = landmarks(n, seed)
    for direction in np.linspace(0, 2 * math.pi, 24, endpoint=False):
        for distance in (0.02, 0.3, 0.8, 1.5):
            heading = direction * 3.0 - 1.0  # headings all around too
            current = Pose(
                GOAL.x + distance * math.cos(direction),
                GOAL.y + distance * math.sin(direction),
                heading,
            )
            m = law(current, points, bisectors)
            world = heading + math.atan2(m[1], m[0])
            assert math.cos(world - (direction + math.pi)) > 0.0, (direction, distance)


def test_many_landmarks_around_give_nearly_the_true_direction():
    points = landmarks(100, 5)
    errors = []
    for direction in np.linspace(0, 2 * math.pi, 24, endpoint=False):
        current = Pose(GOAL.x + 0.5 * math.cos(direction), GOAL.y + 0.5 * math.sin(direction))
        m = law(current, points)
        errors.append(abs(angle_diff(math.atan2(m[1], m[0]), direction + math.pi)))
    assert np.median(errors) < math.radians(5.0)


def test_motion_vector_vanishes_at_the_goal_and_grows_with_the_distance():
    points = landmarks(30, 6)
    assert np.all(law(GOAL, points) == 0.0)
    for direction in (0.0, 1.0, 2.5, 4.0):
        lengths = []
        for distance in (0.005, 0.01, 0.02, 0.05, 0.1, 0.2):
            current = Pose(
                GOAL.x + distance * math.cos(direction), GOAL.y + distance * math.sin(direction)
            )
            lengths.append(float(np.hypot(*law(current, points))))
        assert np.all(np.diff(lengths) > 0)
        assert lengths[1] / lengths[0] == pytest.approx(2.0, rel=0.05)  # linear near the goal


def test_goal_reached_is_a_threshold_on_the_length():
    assert goal_reached([0.003, -0.004], 0.01)
    assert not goal_reached([0.006, -0.008], 0.01)
    assert not goal_reached([0.0, 0.0], 0.0)


def test_longest_increasing():
    values = [3, 1, 4, 1, 5, 9, 2, 6, 5, 3, 5]
    chain = longest_increasing(values)
    picked = [values[i] for i in chain]
    assert len(chain) == 4 and all(a < b for a, b in itertools.pairwise(picked))
    assert chain == sorted(chain)
    assert longest_increasing([]) == []


@pytest.mark.parametrize(
    ("second", "dropped"),
    [
        ([2, 3, 4, 5, 0, 1], [set()]),  # a rotation: nothing changed order
        ([1, 0, 2, 3, 4, 5], [{0}, {1}]),  # two neighbours swapped
        ([4, 5, 0, 2, 1, 3], [{1}, {2}]),  # a swap in a rotated sequence
        ([1, 2, 3, 4, 0, 5], [{0}]),  # one feature jumped ahead
        ([5, 1, 2, 3, 4, 0], [{0}, {5}]),  # a swap across the start of the sequence
        ([0, 3, 2, 1, 4, 5], [{1, 2}, {2, 3}, {1, 3}]),  # a reversed run
    ],
)
def test_circular_lcs_on_hand_made_sequences(second, dropped):
    first = [0, 1, 2, 3, 4, 5]
    kept = longest_common_order(first, second)
    assert set(first) - set(kept) in dropped
    assert kept == sorted(kept)  # in the first order


def _same_circular_order(items, first, second) -> bool:
    a = [x for x in first if x in items]
    b = [x for x in second if x in items]
    k = b.index(a[0])
    return b[k:] + b[:k] == a


def test_circular_lcs_matches_brute_force_on_random_permutations():
    rng = np.random.default_rng(7)
    for _ in range(60):
        n = int(rng.integers(3, 8))
        first, second = list(range(n)), rng.permutation(n).tolist()
        best = max(
            size
            for size in range(1, n + 1)
            for items in itertools.combinations(first, size)
            if _same_circular_order(set(items), first, second)
        )
        kept = longest_common_order(first, second)
        assert len(kept) == best
        assert _same_circular_order(set(kept), first, second)


def test_compiled_rotation_search_is_the_first_longest_rotation():
    # Reference: the LIS of every rotation in Python, the first longest one wins.
    rng = np.random.default_rng(11)
    for n in (1, 2, 5, 40, 150):
        for _ in range(5):
            order = np.argsort(np.arange(n) + rng.normal(0.0, 3.0, n)).astype(np.int64)
            start = rng.integers(n)
            values = np.roll(order, start)
            lengths = [len(longest_increasing(np.roll(values, -k).tolist())) for k in range(n)]
            assert first_longest_rotation(values) == int(np.argmax(lengths))


def test_order_filter_keeps_order_across_minus_pi_and_drops_a_swap():
    goal = np.array([-3.0, -2.0, -1.0, 0.5, 2.0, 3.1])
    current = wrap_angle(goal + 0.5)  # a turn: two features cross +-pi, none changes order
    assert order_filter(current, goal).all()
    current[[1, 2]] = current[[2, 1]]
    kept = order_filter(current, goal)
    assert kept.sum() == 5 and not (kept[1] and kept[2])


def test_the_linear_reading_drops_features_that_cross_the_start_of_the_sequence():
    goal = np.array([-3.0, -2.0, -1.0, 0.5, 2.0, 3.1])
    current = wrap_angle(goal + 0.5)  # 3.1 crosses +-pi, the start of the sequences
    assert order_filter(current, goal).all()  # the circular reading keeps it
    kept = order_filter(current, goal, circular=False)
    assert kept.tolist() == [True, True, True, True, True, False]
    assert longest_common_order([0, 1, 2, 3], [2, 3, 0, 1], circular=False) in ([0, 1], [2, 3])


@pytest.mark.parametrize("turn", [0.0, 0.3, -1.2, math.pi - 0.01, -math.pi + 0.02])
def test_heading_change_is_the_median_shift(turn):
    rng = np.random.default_rng(8)
    goal = rng.uniform(-math.pi, math.pi, 60)
    current = wrap_angle(goal - turn + rng.normal(0.0, 0.3 * COLUMN, 60))
    current[:10] = rng.uniform(-math.pi, math.pi, 10)  # mistracked features: outliers
    assert abs(angle_diff(heading_change(current, goal), turn)) < COLUMN
    assert math.isnan(heading_change([], []))


def test_heading_change_of_a_turn_on_the_spot_from_exact_bearings():
    points = landmarks(20, 9)
    turned = Pose(GOAL.x, GOAL.y, GOAL.heading + 0.8)
    estimate = heading_change(turned.bearing_to(points)[0], GOAL.bearing_to(points)[0])
    assert estimate == pytest.approx(0.8, abs=1e-12)
    assert np.all(law(turned, points) == pytest.approx(0.0, abs=1e-12))


def test_unknown_bisector_frame_is_refused():
    with pytest.raises(ValueError, match="bisectors"):
        sector_vectors([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], "world")
