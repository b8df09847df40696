"""Routes between grid positions: the intermediate views route-based methods track through."""

from __future__ import annotations

import math

import numpy as np

from homebench.geometry import Grid


def grid_route(
    grid: Grid, start: tuple[int, int], end: tuple[int, int], step: float
) -> list[tuple[int, int]]:
    """Grid positions passed on the straight line from ``start`` to ``end`` (both excluded).

    Points every ``step`` grid units along the line are snapped to the nearest grid position
    and repeats dropped, so neighbouring positions follow each other (8-connected for
    ``step`` <= 1). ``step`` <= 0 gives no intermediate positions.
    """
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
