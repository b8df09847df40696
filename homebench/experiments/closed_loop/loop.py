"""One closed-loop trial: see, ask for the home direction, turn and move, until it ends.

Each step: if the true position is within ``success_radius`` of the goal, **success**; if the
path driven has reached the budget, **budget** (give up); after ``max_steps`` steps, **steps**.
Otherwise the robot sees its view (if the homer needs one), asks for the home direction and
steers (:func:`~homebench.experiments.robot.steer`: turn on the spot by at most the turn
limit, or turn onto the direction and drive one step) with the drift model's noise. No
estimate: drive straight on (``continue``, counted) or end with **no_estimate** (``stop``).
A step whose segment leaves the free space (the scene's ``check_pose``, tested every
``CHECK_SPACING`` metres along it) ends the trial at the step's end with **collision** (an
object, the room's walls) or **outside** (beyond what a database shows: its grid's extent).

The path ratio is the path driven over ``start distance - success_radius``, the shortest path
that succeeds: the ``truth`` control without noise drives straight, so its ratio lies in
[1, 1 + step_length / (start distance - success_radius)).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np

from homebench.data.synth.world import PoseError, PoseFault
from homebench.experiments.closed_loop.config import ClosedLoopMotion
from homebench.experiments.closed_loop.homers import Homer
from homebench.experiments.robot import Robot, steer
from homebench.geometry import Pose

Outcome = Literal["success", "budget", "steps", "no_estimate", "collision", "outside"]
OUTCOMES: tuple[Outcome, ...] = get_args(Outcome)
#: Spacing (metres) of the free-space checks along a step.
CHECK_SPACING = 0.01


@dataclass
class LoopResult:
    """A trial's ``outcome``, true ``poses`` (start first), ``path`` driven (m), ``steps``,
    steps without an estimate, and the seconds spent seeing (rendering) and homing."""

    outcome: Outcome
    poses: list[Pose] = field(default_factory=list)
    path: float = 0.0
    steps: int = 0
    no_estimates: int = 0
    see_s: float = 0.0
    home_s: float = 0.0


def segment_fault(a: Pose, b: Pose, check: Callable[[Pose], None]) -> PoseFault | None:
    """Why the segment a -> b is not free (of its first point, every CHECK_SPACING m, that
    ``check`` refuses), or None when it is."""
    n = max(1, math.ceil(math.dist(a.xy, b.xy) / CHECK_SPACING))
    try:
        for t in np.linspace(0.0, 1.0, n + 1)[1:]:
            check(Pose(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), b.heading))
    except PoseError as error:
        return error.fault
    return None


def _ended(robot: Robot, goal: Pose, result: LoopResult, budget: float,
           motion: ClosedLoopMotion) -> Outcome | None:  # fmt: skip
    if math.dist(robot.pose.xy, goal.xy) <= motion.success_radius:
        return "success"
    if result.path >= budget:
        return "budget"
    if result.steps >= motion.max_steps:
        return "steps"
    return None


def run_loop(
    robot: Robot,
    goal: Pose,
    homer: Homer,
    see: Callable[[Pose], np.ndarray],
    check: Callable[[Pose], None],
    motion: ClosedLoopMotion,
) -> LoopResult:
    """Home ``robot`` (at its start) towards ``goal`` steered by ``homer``; the trial."""
    budget = motion.budget(math.dist(robot.pose.xy, goal.xy))
    limits = motion.limits()
    result = LoopResult("steps", [robot.pose])
    while (outcome := _ended(robot, goal, result, budget, motion)) is None:
        started = time.perf_counter()
        image = see(robot.pose) if homer.sees else None
        seen = time.perf_counter()
        direction = homer.direction(robot.pose, image)
        result.see_s += seen - started
        result.home_s += time.perf_counter() - seen
        if direction is None:
            result.no_estimates += 1
            if motion.no_estimate == "stop":
                outcome = "no_estimate"
                break
            direction = 0.0
        before = robot.pose
        robot.execute(steer(direction, motion.step_length, limits))
        result.steps += 1
        result.path += math.dist(before.xy, robot.pose.xy)
        result.poses.append(robot.pose)
        fault = segment_fault(before, robot.pose, check)
        if fault is not None:
            outcome = fault
            break
    result.outcome = outcome
    return result
