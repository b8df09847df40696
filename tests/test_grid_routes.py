"""Grid routes: neighbouring positions from goal to current, endpoints excluded."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.evaluation.grid_routes import grid_route
from homebench.geometry import Grid

GRID = Grid((10, 17), 0.3)


def test_straight_routes_visit_every_position_in_between() -> None:
    assert grid_route(GRID, (2, 3), (2, 7), 0.5) == [(2, 4), (2, 5), (2, 6)]
    assert grid_route(GRID, (5, 3), (1, 3), 0.5) == [(4, 3), (3, 3), (2, 3)]


def test_diagonal_route_is_eight_connected() -> None:
    route = grid_route(GRID, (0, 0), (3, 6), 0.5)
    path = [(0, 0), *route, (3, 6)]
    steps = zip(path, path[1:], strict=False)
    assert all(max(abs(a[0] - b[0]), abs(a[1] - b[1])) == 1 for a, b in steps)


def test_neighbours_and_zero_step_have_no_intermediate_positions() -> None:
    assert grid_route(GRID, (2, 3), (2, 4), 0.5) == []
    assert grid_route(GRID, (2, 3), (2, 9), 0.0) == []


def _all_routes(goal: tuple[int, int], shape: str) -> dict[tuple[int, int], list]:
    return {
        (i, j): grid_route(GRID, goal, (i, j), 0.5, shape)  # type: ignore[arg-type]
        for i in range(GRID.shape[0])
        for j in range(GRID.shape[1])
        if (i, j) != goal
    }


def test_tree_routes_extend_a_shorter_route_of_the_same_goal() -> None:
    goal = (4, 8)
    routes = _all_routes(goal, "tree")
    for end, route in routes.items():
        path = [goal, *route, end]
        steps = zip(path, path[1:], strict=False)
        assert all(max(abs(a[0] - b[0]), abs(a[1] - b[1])) == 1 for a, b in steps)
        if route:  # the route to the view before the end, then that view
            assert route == [*routes[route[-1]], route[-1]]
    # one tracking step per grid position: the routes' edges (prefixes) are the positions
    prefixes = {tuple([*route, end]) for end, route in routes.items()}
    assert len(prefixes) == GRID.size - 1


def test_tree_routes_stay_near_the_straight_line() -> None:
    goal = np.array([4.0, 8.0])
    for end, route in _all_routes((4, 8), "tree").items():
        direction = (np.array(end) - goal) / np.hypot(*(np.array(end) - goal))
        for node in route:
            offset = np.array(node) - goal
            across = abs(offset[0] * direction[1] - offset[1] * direction[0])
            assert across <= 1.5, (end, node)


def test_straight_routes_of_one_goal_do_not_form_a_tree() -> None:
    """The line shape tracks many more edges: what the tree saves."""
    routes = _all_routes((4, 8), "line")
    prefixes = {tuple(route[: k + 1]) for route in routes.values() for k in range(len(route))}
    prefixes |= {tuple([*route, end]) for end, route in routes.items()}
    assert len(prefixes) > 2 * (GRID.size - 1)


def test_unknown_route_shape_is_refused() -> None:
    with pytest.raises(ValueError, match="route shape"):
        grid_route(GRID, (0, 0), (3, 3), 0.5, "zigzag")  # type: ignore[arg-type]


@pytest.mark.slow  # CI time: 26 s of CPU
def test_tree_routes_of_a_wide_grid_need_no_recursion() -> None:
    """A route as long as a 3000-column grid is wide (deeper than Python's recursion limit)."""
    wide = Grid((2, 3000), 0.3)
    route = grid_route(wide, (0, 0), (1, 2999), 0.5, "tree")
    assert route[0] in {(0, 1), (1, 1)} and route[-1] in {(0, 2998), (1, 2998)}
    assert len(route) == 2998
