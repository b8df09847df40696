"""Return ratio and catchment on hand-made home-vector fields whose outcomes are known."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.analysis.metrics import HomeField
from homebench.analysis.return_ratio import catchment, return_ratio
from homebench.geometry import Grid, holed_grid

GRID = Grid((10, 17), 0.3, origin=(-1.0, 0.5))
N = GRID.size


def constant(goal: tuple[int, int], angle: float, grid: Grid = GRID) -> HomeField:
    return HomeField(grid, goal, np.full(grid.shape, angle))


def only(mask: np.ndarray) -> np.ndarray:
    """The (nx, ny) bool array that is True exactly where ``mask`` is."""
    return np.broadcast_to(mask, GRID.shape)


II, JJ = np.indices(GRID.shape)


# --------------------------------------------------------------------------- return ratio


@pytest.mark.parametrize("goal", [(0, 0), (9, 16), (0, 16), (5, 8), (1, 4), (8, 3), (7, 13)])
def test_perfect_field_returns_from_everywhere(goal):
    result = return_ratio(HomeField.ideal(GRID, goal))
    assert result.rr == 1.0
    assert result.success.all() and result.started.all()
    assert not result.no_estimate.any()
    assert result.path_length[goal] == 0.0


def test_perfect_field_returns_for_every_goal_even_without_goal_entry():
    for goal in GRID.indices():
        f = HomeField.ideal(GRID, goal)
        angles = f.angles.copy()
        angles[goal] = np.nan  # the goal's own entry is never used
        assert return_ratio(HomeField(GRID, goal, angles)).rr == 1.0, goal
        assert return_ratio(HomeField(GRID, goal, angles + 0.3)).rr == 1.0, goal


def test_field_pointing_away_only_goal_succeeds():
    goal = (5, 8)
    result = return_ratio(HomeField(GRID, goal, HomeField.ideal(GRID, goal).angles + np.pi))
    assert result.rr == pytest.approx(1 / N)
    assert np.array_equal(result.success, only((II == 5) & (JJ == 8)))
    # every other robot walks off for more than half the perimeter: 25 grid units -> 32 steps
    assert np.allclose(result.path_length[~result.success], 32 * 0.8)


@pytest.mark.parametrize(
    ("angle", "goal", "line"),
    [
        (0.0, (9, 6), (JJ == 6)),  # +x: the goal's row, left of it
        (np.pi, (0, 6), (JJ == 6)),  # -x
        (np.pi / 2, (4, 16), (II == 4)),  # +y: the goal's column, below it
        (-np.pi / 2, (4, 0), (II == 4)),  # -y
    ],
)
def test_uniform_field_succeeds_only_on_the_line_into_the_goal(angle, goal, line):
    result = return_ratio(constant(goal, angle))
    assert np.array_equal(result.success, only(line))
    assert result.rr == pytest.approx(line.sum() / N)
    assert not result.no_estimate.any()


def test_uniform_field_path_length_and_trajectory_in_metres():
    result = return_ratio(constant((9, 6), 0.0), starts=[(0, 6), (9, 6)], keep_trajectories=True)
    assert result.started.sum() == 2 and result.rr == 1.0
    # from i = 0 the robot stops at x = 8.8 grid units, 0.2 from the goal: 11 steps
    assert result.path_length[0, 6] == pytest.approx(11 * 0.8)
    assert result.path_length[9, 6] == 0.0
    assert np.isnan(result.path_length[1, 6]) and not result.success[1, 6]
    np.testing.assert_array_equal(result.starts, [[0, 6], [9, 6]])
    traj = result.trajectories
    assert traj.shape == (2, 12, 2)
    np.testing.assert_allclose(traj[0, 0], GRID.position(0, 6))
    np.testing.assert_allclose(traj[0, -1], GRID.position(8.8, 6), atol=1e-12)
    np.testing.assert_allclose(traj[0, 1] - traj[0, 0], [0.8 * 0.3, 0.0], atol=1e-12)
    np.testing.assert_allclose(traj[1], np.broadcast_to(GRID.position(9, 6), (12, 2)))


def test_outcomes_per_start_match_the_grid_arrays():
    angles = np.full(GRID.shape, 0.0)
    angles[6, 2] = np.nan
    result = return_ratio(HomeField(GRID, (9, 6), angles), starts=[(9, 6), (0, 6), (0, 2)])
    out = result.outcomes()
    np.testing.assert_array_equal(out["start_i"], [0, 0, 9])  # row-major, as ``starts``
    np.testing.assert_array_equal(out["start_j"], [2, 6, 6])
    np.testing.assert_array_equal(out["steps"], [7, 11, 0])
    np.testing.assert_array_equal(out["success"], [False, True, True])
    np.testing.assert_allclose(out["path_length"], [7 * 0.8, 11 * 0.8, 0.0])
    np.testing.assert_array_equal(out["no_estimate"], [True, False, False])
    assert {len(v) for v in out.values()} == {3}


def test_half_field_along_x():
    goal = (2, 8)
    angles = np.where(II < 5, HomeField.ideal(GRID, goal).angles, 0.0)  # other half: +x, away
    result = return_ratio(HomeField(GRID, goal, angles))
    assert np.array_equal(result.success, II < 5)
    assert result.rr == 0.5


def test_half_field_along_y():
    goal = (4, 3)
    angles = np.where(JJ < 8, HomeField.ideal(GRID, goal).angles, np.pi / 2)  # +y, away
    result = return_ratio(HomeField(GRID, goal, angles))
    assert np.array_equal(result.success, JJ < 8)
    assert result.rr == pytest.approx(80 / N)


def test_missing_estimates_fail_and_are_counted():
    goal = (2, 8)
    angles = np.where(II < 5, HomeField.ideal(GRID, goal).angles, np.nan)
    result = return_ratio(HomeField(GRID, goal, angles))
    assert np.array_equal(result.success, II < 5)
    assert np.array_equal(result.no_estimate, II >= 5)
    assert (result.path_length[II >= 5] == 0).all()


def test_robot_steered_into_a_missing_estimate_fails_there():
    angles = np.full(GRID.shape, 0.0)
    angles[6, 2] = np.nan
    result = return_ratio(HomeField(GRID, (9, 2), angles), starts=[(0, 2)])
    assert not result.success[0, 2] and result.no_estimate[0, 2]
    assert result.path_length[0, 2] == pytest.approx(7 * 0.8)  # x = 5.6 is nearest to i = 6


def _abstains_next_to_goal(goal: tuple[int, int]) -> HomeField:
    """The ideal field towards ``goal`` without an estimate at its 8 grid neighbours (what
    warping gives where rho = 0 wins: the view looks like home)."""
    angles = HomeField.ideal(GRID, goal).angles.copy()
    near = (np.abs(II - goal[0]) <= 1) & (np.abs(JJ - goal[1]) <= 1)
    angles[near] = np.nan
    return HomeField(GRID, goal, angles)


def test_abstention_next_to_the_goal_fails_by_default_and_arrives_when_asked():
    field = _abstains_next_to_goal((5, 8))
    failed = return_ratio(field)
    assert failed.rr == pytest.approx(1 / N)  # every walk ends on a neighbour without estimate
    assert failed.no_estimate.sum() == N - 1
    arrived = return_ratio(field, no_estimate="arrived")
    assert arrived.rr == 1.0
    np.testing.assert_array_equal(arrived.no_estimate, failed.no_estimate)  # same walks end
    np.testing.assert_array_equal(arrived.path_length, failed.path_length)


def test_abstention_arrives_only_at_the_goals_grid_neighbours():
    goal = (5, 8)
    angles = HomeField.ideal(GRID, goal).angles.copy()
    angles[(II == 3) & (JJ == 8)] = np.nan  # two positions from the goal
    result = return_ratio(HomeField(GRID, goal, angles), no_estimate="arrived")
    assert not result.success[3, 8] and result.no_estimate[3, 8]
    assert not result.success[0, 8] and result.no_estimate[0, 8]  # walks through (3, 8)
    everywhere = HomeField(GRID, goal, np.full(GRID.shape, np.nan))
    assert return_ratio(everywhere, no_estimate="arrived").rr == pytest.approx(9 / N)


def test_unknown_no_estimate_reading_is_refused():
    with pytest.raises(ValueError, match="no_estimate"):
        return_ratio(constant((0, 0), 0.0), no_estimate="ignore")


def test_success_radius_rescues_a_slightly_off_field():
    # 5 degrees off +x from (0, 6) towards (9, 6): closest pass after 11 steps, at
    # (8.767, 6.767), 0.80 grid units from the goal; the next step is 1.01 away.
    field = constant((9, 6), np.radians(5.0))
    assert not return_ratio(field, starts=[(0, 6)]).success[0, 6]
    assert not return_ratio(field, starts=[(0, 6)], success_radius=0.79).success[0, 6]
    hit = return_ratio(field, starts=[(0, 6)], success_radius=0.81)
    assert hit.success[0, 6] and hit.path_length[0, 6] == pytest.approx(11 * 0.8)


def test_step_length_matters():
    # along +x from i = 0 with radius 0.1: steps of 0.8 pass 0.2 and 0.6 from the goal at 9,
    # steps of 0.9 or 1.0 land on it
    field = constant((9, 6), 0.0)
    assert not return_ratio(field, success_radius=0.1, starts=[(0, 6)]).success[0, 6]
    assert return_ratio(field, rh=0.9, success_radius=0.1, starts=[(0, 6)]).success[0, 6]
    assert return_ratio(field, rh=1.0, success_radius=0.1, starts=[(0, 6)]).success[0, 6]


def test_max_travel_limits_a_spiralling_field():
    goal = (5, 8)
    field = HomeField(GRID, goal, HomeField.ideal(GRID, goal).angles + np.radians(45.0))
    free = return_ratio(field, max_travel=1000.0)
    assert free.rr > 0.95
    for limit in (25.0, 10.0, 4.0):
        limited = return_ratio(field, max_travel=limit)
        # a robot arriving after k steps had to be allowed its k-th step: (k - 1) * rh <= limit
        expected = free.success & (free.path_length - 0.8 <= limit + 1e-9)
        assert np.array_equal(limited.success, expected)
        assert np.allclose(limited.path_length[~expected], (np.floor(limit / 0.8) + 1) * 0.8)
    assert return_ratio(field, max_travel=4.0).rr < return_ratio(field).rr


def test_circling_field_never_arrives():
    goal = (5, 8)
    field = HomeField(GRID, goal, HomeField.ideal(GRID, goal).angles + np.pi / 2)
    result = return_ratio(field, max_travel=7.0)
    assert result.rr == pytest.approx(1 / N)
    assert np.allclose(result.path_length[~result.success], 9 * 0.8)


def test_bad_arguments():
    field = constant((0, 0), 0.0)
    with pytest.raises(ValueError, match="rh"):
        return_ratio(field, rh=0.0)
    with pytest.raises(ValueError, match="rh"):
        return_ratio(field, success_radius=-1.0)
    with pytest.raises(ValueError, match="starts"):
        return_ratio(field, starts=[(10, 0)])
    with pytest.raises(ValueError, match="starts"):
        return_ratio(field, starts=np.zeros((0, 2)))


# --------------------------------------------------------------------------- catchment


def test_perfect_field_catchment_is_one_for_every_goal():
    for goal in GRID.indices():
        result = catchment(HomeField.ideal(GRID, goal))
        assert result.ratio == 1.0 and result.success.all(), goal


def test_catchment_away_field_only_goal():
    goal = (5, 8)
    result = catchment(HomeField(GRID, goal, HomeField.ideal(GRID, goal).angles + np.pi))
    assert np.array_equal(result.success, only((II == 5) & (JJ == 8)))
    assert result.ratio == pytest.approx(1 / N)


@pytest.mark.parametrize(
    ("angle", "goal", "line"),
    [
        (0.0, (9, 6), (JJ == 6)),
        (np.pi, (0, 6), (JJ == 6)),
        (np.pi / 2, (4, 16), (II == 4)),
        (-np.pi / 2, (4, 0), (II == 4)),
        (np.pi / 4, (9, 16), (JJ - II == 7)),  # the diagonal into the top-right corner
        (-3 * np.pi / 4, (0, 0), (II == JJ)),
        (3 * np.pi / 4, (0, 12), (II + JJ == 12)),
    ],
)
def test_catchment_uniform_fields(angle, goal, line):
    result = catchment(constant(goal, angle))
    assert np.array_equal(result.success, only(line))


def test_catchment_cycle_and_missing_fail():
    grid = Grid((3, 3), 1.0)
    angles = HomeField.ideal(grid, (0, 0)).angles.copy()
    angles[1, 2], angles[2, 2] = 0.0, np.pi  # (1, 2) <-> (2, 2)
    result = catchment(HomeField(grid, (0, 0), angles))
    expected = np.ones((3, 3), dtype=bool)
    expected[1, 2] = expected[2, 2] = False
    assert np.array_equal(result.success, expected)
    assert result.ratio == pytest.approx(7 / 9)

    line = Grid((5, 1), 1.0)
    angles = np.array([[np.nan], [np.pi], [np.nan], [np.pi], [np.pi]])  # goal entry unused
    result = catchment(HomeField(line, (0, 0), angles))
    np.testing.assert_array_equal(result.success[:, 0], [True, True, False, False, False])


def test_on_a_grid_with_holes_rr_steers_past_them_and_catchment_fails_on_them():
    """README, Brains on Board: trials start at the positions present; the return-ratio robot
    steers by the nearest position present, Möller's variant fails on stepping onto a hole."""
    line = holed_grid((5, 1), 1.0, (0.0, 0.0), [(2, 0)])
    field = HomeField.ideal(line, (0, 0))  # the hole's entry is never read
    rr = return_ratio(field)
    assert rr.rr == 1.0 and rr.started[:, 0].tolist() == [True, True, False, True, True]
    assert rr.starts.tolist() == [[0, 0], [1, 0], [3, 0], [4, 0]]
    assert rr.success[4, 0] and rr.path_length[4, 0] == pytest.approx(4.0, abs=0.8)
    result = catchment(field)
    np.testing.assert_array_equal(result.success[:, 0], [True, True, False, False, False])
    assert result.ratio == pytest.approx(2 / 4)  # of the positions present
    with pytest.raises(ValueError, match="starts"):
        return_ratio(field, starts=[(2, 0)])

    holed = holed_grid(GRID.shape, GRID.spacing, GRID.origin, [(5, 8), (0, 3)])
    assert return_ratio(HomeField.ideal(holed, (7, 13))).rr == 1.0
    assert catchment(HomeField.ideal(holed, (0, 0))).ratio < 1.0  # (0, 3) cuts (0, 4..) off


def test_catchment_ties_go_to_the_axis_neighbour():
    grid = Grid((3, 3), 1.0)
    angles = np.full((3, 3), np.nan)
    angles[0, 0] = np.pi / 8  # half-way between +x and the diagonal
    angles[2, 0] = 3 * np.pi / 8  # half-way between the diagonal and +y
    assert catchment(HomeField(grid, (1, 0), angles)).success[0, 0]
    assert catchment(HomeField(grid, (2, 1), angles)).success[2, 0]
