"""Routes between grid positions: the intermediate views route-based methods track through.

Two shapes (:data:`RouteShape`). ``line``: the grid positions passed on the straight line from
the start to the end. ``tree``: the route to the last position before the end on that line,
then that position, so every route from one start extends a shorter one and the routes from a
start form a tree with one edge per grid position: a method that tracks features along routes
tracks them once per position (its routes still follow the line to within about a grid unit).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import get_args

import numpy as np

from homebench.geometry import Grid
from homebench.methods.base import RouteShape

ROUTE_SHAPES: tuple[RouteShape, ...] = get_args(RouteShape)


def grid_route(
    grid: Grid,
    start: tuple[int, int],
    end: tuple[int, int],
    step: float,
    shape: RouteShape = "line",
) -> list[tuple[int, int]]:
    """Grid positions on the route of ``shape`` from ``start`` to ``end`` (both excluded).

    ``line``: points every ``step`` grid units along the straight line are snapped to the
    nearest grid position and repeats dropped, so neighbouring positions follow each other
    (8-connected for ``step`` <= 1). ``tree``: the ``tree`` route to the last of those
    positions, then that position (8-connected too). ``step`` <= 0 gives no intermediate
    positions.
    """
    if shape == "tree":
        return list(_tree_route(grid, tuple(start), tuple(end), float(step)))
    if shape != "line":
        raise ValueError(f"unknown route shape {shape!r}; choose from {ROUTE_SHAPES}")
    return _line_route(grid, start, end, step)


def method_route(
    method: object, grid: Grid, goal: tuple[int, int], current: tuple[int, int]
) -> list[tuple[int, int]]:
    """The intermediate positions a route-based method (``uses_route``) tracks through from
    ``goal`` to ``current``: its ``route_step`` (default 0: none) and ``route_shape`` (default
    ``line``); [] for other methods."""
    if not getattr(method, "uses_route", False):
        return []
    step = float(getattr(method, "route_step", 0.0))
    return grid_route(grid, goal, current, step, getattr(method, "route_shape", "line"))


def _line_route(
    grid: Grid, start: tuple[int, int], end: tuple[int, int], step: float
) -> list[tuple[int, int]]:
    if step <= 0:
        return []
    a = np.asarray(start, dtype=np.float64)
    b = np.asarray(end, dtype=np.float64)
    n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
    points = a + np.linspace(0.0, 1.0, n + 1)[:, None] * (b - a)
    nodes: list[tuple[int, int]] = []
    for i, j in np.rint(points).astype(int):
        node = (int(i), int(j))
        if node not in (tuple(start), tuple(end)) and (not nodes or nodes[-1] != node):
            nodes.append(node)
    return [node for node in nodes if grid.contains(*node)]


def _tree_route(
    grid: Grid, start: tuple[int, int], end: tuple[int, int], step: float
) -> tuple[tuple[int, int], ...]:
    """The ``tree`` route: the chain of last-positions-before from ``end`` back to ``start``,
    walked without recursion (a route may be as long as the grid is wide)."""
    parents: list[tuple[int, int]] = []
    node, prefix = end, ()
    while (parent := _parent(grid, start, node, step)) is not None:
        if _squared(parent, start) >= _squared(node, start):  # the guard: a straight route
            prefix = tuple(_line_route(grid, start, node, step))
            break
        parents.append(parent)
        node = parent
    return (*prefix, *reversed(parents))


@lru_cache(maxsize=1 << 16)
def _parent(
    grid: Grid, start: tuple[int, int], node: tuple[int, int], step: float
) -> tuple[int, int] | None:
    """The last position before ``node`` on the line from ``start`` (None: none between).
    With ``step`` <= 1 it is ``node`` moved towards ``start`` by at most a column and a row
    (checked on every pair of a 12 x 17 grid), so closer to ``start`` and the walk ends; the
    guard in :func:`_tree_route` ends it for any step. Cached: a start's routes share their
    prefixes."""
    line = _line_route(grid, start, node, step)
    return line[-1] if line else None


def _squared(a: tuple[int, int], b: tuple[int, int]) -> int:
    return (a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2
