"""How a robot's homing ends when it neither arrives nor runs out of steps: it turns on the
spot without stepping (``turning``), or it leaves what the scene can show, a recording's reach
or a grid's extent (``outside``), which is not a collision with anything.

Found on a replayed Ant World route (every 8th pose of BoB's ant1_route1, read with BoB's
conventions): Infomax at its default rate found two directions about as familiar, one each side
of its heading, and turned +10 deg, -10 deg, ... for 600 steps; warping and min-warping left the
0.3 m reach of the recording on their first legs and were called collisions.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from homebench.data.synth.world import PoseError
from homebench.experiments.closed_loop.config import ClosedLoopMotion
from homebench.experiments.closed_loop.homers import TruthHomer
from homebench.experiments.closed_loop.loop import run_loop
from homebench.experiments.robot import DriftModel, MotionLimits, Robot
from homebench.experiments.route.pairwise import (
    FollowParams,
    LegRun,
    PairwiseHoming,
    Target,
    drive_leg,
)
from homebench.geometry import Pose
from homebench.methods.base import HomingEstimate

VIEW = np.arange(24 * 8, dtype=np.uint8).reshape(8, 24)


def _robot() -> Robot:
    return Robot.at(Pose(0.0, 0.0, 0.0), DriftModel(), np.random.default_rng(0))


def _leg(robot: Robot, steer_by, look, params: FollowParams, limits: MotionLimits):
    target = Target(frame=0, image=np.zeros_like(VIEW), homer=None, pose=Pose(5.0, 0.0, 0.0))
    result = PairwiseHoming([robot.pose])
    leg = LegRun(target, robot)
    status, _ = drive_leg(robot, leg, steer_by, look, limits, params, 500, result, VIEW)
    return status, leg, result


def test_a_direction_that_jumps_past_the_turn_limit_ends_as_turning() -> None:
    """The estimate is 15 deg left when the robot's heading is even tens of degrees, 15 deg
    right when odd: every step turns 10 deg one way, then back. A full turn's worth of steps
    (36 at 10 deg) that only turn end the leg."""
    limits = MotionLimits(step_length=0.05, max_turn_deg=10.0)

    def alternating(pose: Pose, image: np.ndarray) -> HomingEstimate:
        odd = round(math.degrees(pose.heading) / 10.0) % 2
        return HomingEstimate(angle=math.radians(-15.0 if odd else 15.0))

    robot = _robot()
    status, leg, _ = _leg(robot, alternating, lambda pose, k: VIEW, FollowParams(), limits)
    assert status == "turning" and leg.steps == 36
    assert robot.pose.xy == pytest.approx((0.0, 0.0))
    status, leg, _ = _leg(
        _robot(), alternating, lambda pose, k: VIEW, FollowParams(max_turn_only=5), limits
    )
    assert status == "turning" and leg.steps == 5


def test_a_turn_that_ends_in_a_step_starts_the_count_again() -> None:
    """Turning 30 deg at 10 deg a step, then stepping, again and again: never turning."""
    limits = MotionLimits(step_length=0.05, max_turn_deg=10.0)
    steps = iter(range(10_000))

    def turn_then_step(pose: Pose, image: np.ndarray) -> HomingEstimate:
        return HomingEstimate(angle=math.radians(25.0) if next(steps) % 4 == 0 else 0.0)

    status, leg, _ = _leg(
        _robot(), turn_then_step, lambda pose, k: VIEW, FollowParams(max_turn_only=3), limits
    )
    assert status == "steps" and leg.steps == 500


@pytest.mark.parametrize("fault", ["outside", "collision"])
def test_a_pose_the_scene_cannot_show_ends_with_the_scenes_reason(fault: str) -> None:
    def look(pose: Pose, k: int) -> np.ndarray:
        if pose.x > 0.12:
            raise PoseError(f"pose ({pose.x:.2f}, {pose.y:.2f}) m: {fault}", fault)  # type: ignore[arg-type]
        return VIEW

    ahead = lambda pose, image: HomingEstimate(angle=0.0)  # noqa: E731
    status, leg, result = _leg(_robot(), ahead, look, FollowParams(), MotionLimits())
    assert status == fault and leg.steps == 3 and len(result.poses) == 4


def test_leaving_a_grid_ends_a_closed_loop_trial_outside_not_in_collision() -> None:
    def grid_until(pose: Pose) -> None:
        if pose.x > 1.0:
            raise PoseError("more than one spacing outside the grid", "outside")

    goal = Pose(2.0, 0.0)
    result = run_loop(_robot(), goal, TruthHomer(goal), lambda pose: VIEW, grid_until,
                      ClosedLoopMotion(step_length=0.125))  # fmt: skip
    assert result.outcome == "outside" and result.steps == 9


def test_a_pose_error_keeps_its_reason_across_processes() -> None:
    error = pickle.loads(pickle.dumps(PoseError("beyond the recording's reach", "outside")))
    assert error.fault == "outside" and str(error) == "beyond the recording's reach"
    assert PoseError("inside an object").fault == "collision"
