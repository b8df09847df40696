"""Neighbour pairs of a capture grid: the homing problems whose true answers the grid gives."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from homebench.geometry import Grid

Axis = Literal["x", "y"]
GridIndex = tuple[int, int]


@dataclass(frozen=True)
class NeighbourPair:
    """A current and a goal position one grid step apart along ``axis``."""

    current: GridIndex
    goal: GridIndex
    axis: Axis

    @property
    def way(self) -> str:
        """Which way the goal lies: "+x", "-x", "+y" or "-y" (grid index growing or not)."""
        k = 0 if self.axis == "x" else 1
        return ("+" if self.goal[k] > self.current[k] else "-") + self.axis


@dataclass(frozen=True)
class PlacePair:
    """Two posed images, addressed as places (k, 0), and the ``way`` the goal lies: the axis
    and sign ("+x", ..., "-y") of the world direction's larger component."""

    current: GridIndex
    goal: GridIndex
    way: str


Pair = NeighbourPair | PlacePair


def _edges(grid: Grid, axis: Axis) -> list[tuple[GridIndex, GridIndex]]:
    """Every pair of positions one step apart along ``axis``, once, lower index first."""
    di, dj = (1, 0) if axis == "x" else (0, 1)
    return [((i, j), (i + di, j + dj)) for i, j in grid.indices() if grid.contains(i + di, j + dj)]


def neighbour_pairs(grid: Grid, per_axis: int, seed: int = 0) -> list[NeighbourPair]:
    """At most ``per_axis`` pairs of neighbours along x and as many along y, drawn without
    replacement (seeded), each homed one way round, the way drawn (current or goal first)."""
    rng = np.random.default_rng(seed)
    pairs = []
    for axis in ("x", "y"):
        edges = _edges(grid, axis)
        picked = rng.permutation(len(edges))[:per_axis]
        flips = rng.random(picked.size) < 0.5
        for k, flip in zip(picked, flips, strict=True):
            a, b = edges[k]
            pairs.append(NeighbourPair(*((b, a) if flip else (a, b)), axis))
    return pairs


def first_per_axis(pairs: list[NeighbourPair], n: int) -> list[int]:
    """Indices into ``pairs`` of the first ``n`` pairs along each axis."""
    taken = {"x": 0, "y": 0}
    picked = []
    for k, pair in enumerate(pairs):
        if taken[pair.axis] < n:
            taken[pair.axis] += 1
            picked.append(k)
    return picked
