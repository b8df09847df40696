"""Grid routes: neighbouring positions from goal to current, endpoints excluded."""

from __future__ import annotations

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
