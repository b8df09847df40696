"""Goals and starts of a closed-loop run in the world frame, and the floor they stand for.

A lattice start stands for its cell (spacing^2, centred on it); a random start for
region area / number drawn. Starts outside the free space (the scene's ``check_pose``) are
dropped but keep their index, so the same config gives the same start numbers in every style.
Headings are uniform in [-pi, pi), seeded per start index, unless the config fixes them: every
method and style sees the same start poses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homebench.data.synth.world import PoseError
from homebench.errors import ConfigError
from homebench.experiments.closed_loop.config import (
    ClosedLoopConfig,
    GoalSpec,
    LatticeStarts,
    RandomStarts,
    Region,
)
from homebench.experiments.scene import Scene
from homebench.geometry import Grid, Pose
from homebench.hashing import derived_seed


@dataclass(frozen=True)
class Start:
    """Start ``index``: pose (world frame, metres, rad), lattice ``cell`` (column, row) or
    None for random starts, and the floor ``area`` (m^2) it stands for."""

    index: int
    x: float
    y: float
    heading: float
    cell: tuple[int, int] | None
    area: float

    @property
    def pose(self) -> Pose:
        return Pose(self.x, self.y, self.heading)


def _grid(scene: Scene) -> Grid:
    assert scene.grid is not None, "closed-loop scenes know their capture grid"
    return scene.grid


def world_region(config: ClosedLoopConfig, scene: Scene) -> Region:
    """The starts' region in the world frame (default: the capture grid's extent)."""
    region = config.starts.region
    grid = _grid(scene)
    if region is None:
        far = grid.position(grid.shape[0] - 1, grid.shape[1] - 1)
        return (*grid.origin, float(far[0]), float(far[1]))
    dx, dy = grid.origin if config.frame == "grid" else (0.0, 0.0)
    return (region[0] + dx, region[1] + dy, region[2] + dx, region[3] + dy)


def goal_pose(config: ClosedLoopConfig, goal: GoalSpec, scene: Scene) -> Pose:
    """A goal's pose in the world frame."""
    grid = _grid(scene)
    if goal.grid is not None:
        i, j = goal.grid
        if not grid.contains(i, j):
            raise ConfigError(f"goal {list(goal.grid)} is outside the {grid.shape} capture grid")
        x, y = (float(v) for v in grid.position(i, j))
    else:
        assert goal.at is not None
        dx, dy = grid.origin if config.frame == "grid" else (0.0, 0.0)
        x, y = goal.at[0] + dx, goal.at[1] + dy
    return Pose(x, y, math.radians(goal.heading_deg))


def _heading(spec: LatticeStarts | RandomStarts, seed: int, index: int) -> float:
    """The configured heading, or one uniform in [-pi, pi) seeded by (seed, index)."""
    if spec.heading_deg is not None:
        return math.radians(spec.heading_deg)
    return float(np.random.default_rng(derived_seed(seed, "heading", index)).uniform(-np.pi, np.pi))


def candidate_starts(config: ClosedLoopConfig, region: Region) -> list[Start]:
    """Every start of the config over ``region`` (world frame), free or not, in index order;
    ConfigError when there are more trials than one run can hold."""
    problem = config.count_problem(region)
    if problem:
        raise ConfigError(problem)
    x0, y0, x1, y1 = region
    spec = config.starts
    if isinstance(spec, LatticeStarts):
        nx, ny = spec.shape(region)
        area = spec.spacing**2
        return [
            Start(r * nx + c, x0 + c * spec.spacing, y0 + r * spec.spacing,
                  _heading(spec, config.seed, r * nx + c), (c, r), area)
            for r in range(ny)
            for c in range(nx)
        ]  # fmt: skip
    rng = np.random.default_rng(derived_seed(spec.seed, "starts"))
    xy = rng.uniform((x0, y0), (x1, y1), size=(spec.random, 2))
    area = (x1 - x0) * (y1 - y0) / spec.random
    return [
        Start(k, float(x), float(y), _heading(spec, spec.seed, k), None, area)
        for k, (x, y) in enumerate(xy)
    ]


def free_starts(config: ClosedLoopConfig, scene: Scene) -> list[Start]:
    """The config's starts that lie in the scene's free space."""
    starts = []
    for start in candidate_starts(config, world_region(config, scene)):
        try:
            scene.check_pose(start.pose)
        except PoseError:
            continue
        starts.append(start)
    return starts


def goal_starts(starts: list[Start], goal: Pose, floor: float) -> list[Start]:
    """The starts at least ``floor`` metres from ``goal`` (to within a nanometre, so that a
    lattice node ``floor`` away counts whatever its rounding)."""
    return [s for s in starts if math.dist((s.x, s.y), goal.xy) >= floor - 1e-9]
