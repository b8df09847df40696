"""The route-homing robot: kinematics, the drift model, steering, dead reckoning.

Ground truth: hand-computed poses, and for the random errors their variances (linear in the
distance driven), estimated from many seeded runs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.experiments.robot import (
    DriftModel,
    Motion,
    MotionLimits,
    Robot,
    apply_motion,
    dead_reckon,
    drive_to,
    steer,
    turn_to,
)
from homebench.geometry import Pose

LIMITS = MotionLimits(step_length=0.05, max_turn_deg=10.0)


def test_apply_motion_turns_then_drives_along_the_mean_heading() -> None:
    pose = apply_motion(Pose(1.0, 2.0, 0.0), Motion(math.pi / 2, 1.0))
    assert (pose.x, pose.y, pose.heading) == pytest.approx((1.0, 3.0, math.pi / 2))
    drifted = apply_motion(Pose(0.0, 0.0, 0.0), Motion(0.0, 2.0, drift=0.2))
    assert (drifted.x, drifted.y) == pytest.approx((2 * math.cos(0.1), 2 * math.sin(0.1)))
    assert drifted.heading == pytest.approx(0.2)


def test_steer_respects_the_limits_and_lands_on_the_target() -> None:
    assert steer(0.0, 1.0, LIMITS) == Motion(0.0, 0.05)
    assert steer(0.0, 0.02, LIMITS) == Motion(0.0, 0.02)  # the last step is exact
    behind = steer(math.radians(170.0), 1.0, LIMITS)
    assert behind.turn == pytest.approx(math.radians(10.0)) and behind.forward == 0.0
    right = steer(math.radians(-30.0), 1.0, LIMITS)  # turns on the spot first
    assert right.turn == pytest.approx(math.radians(-10.0)) and right.forward == 0.0
    slight = steer(math.radians(-7.0), 1.0, LIMITS)  # within one turn: onto it, then straight
    assert slight.turn == pytest.approx(math.radians(-7.0)) and slight.forward == 0.05


def test_a_target_straight_behind_is_turned_to_one_way_not_rocked_at() -> None:
    """A U-turn: the wrapped direction of a target behind flips between +pi and -pi with
    rounding; the robot must keep turning one way and reach it (it rocked on the spot)."""
    for almost_pi in (math.pi - 1e-12, -math.pi, -math.pi + 1e-12):
        assert steer(almost_pi, 1.0, LIMITS).turn == pytest.approx(math.radians(10.0))
    slow = MotionLimits(step_length=0.05, max_turn_deg=3.75)  # the paper's 3 deg/s, 0.8 fps
    robot = Robot.at(Pose(0.5, 4.5, 0.0), DriftModel(), np.random.default_rng(0))
    robot.execute(Motion(math.pi / 2, 0.0))  # facing +y; the target lies straight behind
    steps = sum(1 for _ in drive_to(robot, (0.5, 3.5), slow, by_odometry=False, tolerance=0.01))
    assert steps == 47 + 20  # 47 turns on the spot; the 48th turn starts the 20 steps of 5 cm
    assert math.dist(robot.pose.xy, (0.5, 3.5)) <= 0.01


def test_zero_drift_gives_exact_dead_reckoning() -> None:
    rng = np.random.default_rng(1)
    robot = Robot.at(Pose(2.0, 3.0, 0.4), DriftModel(), np.random.default_rng(2))
    for turn, forward in zip(rng.uniform(-0.3, 0.3, 50), rng.uniform(0, 0.1, 50), strict=True):
        robot.execute(Motion(float(turn), float(forward)))
        assert robot.pose == robot.odometry
    truth, belief = dead_reckon(robot, Pose(2.0, 3.0, 0.4), LIMITS)
    assert truth == belief and len(truth) > 1
    assert (robot.pose.x, robot.pose.y) == pytest.approx((2.0, 3.0), abs=1e-9)
    assert robot.pose.heading == pytest.approx(0.4, abs=1e-12)


def test_drive_to_by_the_truth_reaches_the_target_despite_noise() -> None:
    drift = DriftModel(translation_var=1e-4, rotation_var=1e-3, scale_bias=0.05)
    robot = Robot.at(Pose(0.0, 0.0, 0.0), drift, np.random.default_rng(3))
    list(drive_to(robot, (1.0, 1.0), LIMITS, by_odometry=False, tolerance=0.01))
    assert math.dist((robot.pose.x, robot.pose.y), (1.0, 1.0)) <= 0.01
    assert math.dist((robot.odometry.x, robot.odometry.y), (1.0, 1.0)) > 0.01


def _straight_errors(drift: DriftModel, length: float, runs: int) -> np.ndarray:
    """(runs, 3): along-track, cross-track and heading error after commanding ``length`` m."""
    rows = []
    for k in range(runs):
        robot = Robot.at(Pose(0.0, 0.0, 0.0), drift, np.random.default_rng([7, k]))
        list(drive_to(robot, (length, 0.0), LIMITS, by_odometry=True))
        rows.append((robot.pose.x - length, robot.pose.y, robot.pose.heading))
    return np.asarray(rows)


def test_random_drift_variance_grows_linearly_with_distance() -> None:
    drift = DriftModel(translation_var=1e-4, rotation_var=4e-4)
    runs = 300
    for length in (1.0, 4.0):
        errors = _straight_errors(drift, length, runs)
        assert np.var(errors[:, 0]) == pytest.approx(1e-4 * length, rel=0.25)
        assert np.var(errors[:, 2]) == pytest.approx(4e-4 * length, rel=0.25)
    short, long = (_straight_errors(drift, x, 100) for x in (1.0, 4.0))
    assert np.mean(np.hypot(long[:, 0], long[:, 1])) > 2 * np.mean(
        np.hypot(short[:, 0], short[:, 1])
    )


def test_systematic_drift_grows_with_distance() -> None:
    drift = DriftModel(scale_bias=0.02, heading_bias=0.01)
    errors = [_straight_errors(drift, length, 1)[0] for length in (1.0, 2.0, 4.0)]
    assert [e[2] for e in errors] == pytest.approx([0.01, 0.02, 0.04])  # heading: bias x length
    sizes = [math.hypot(e[0], e[1]) for e in errors]
    assert sizes[0] < sizes[1] < sizes[2]
    assert errors[2][1] == pytest.approx(0.01 * 4.0**2 / 2, rel=0.05)  # ccw drift bends left


def test_turn_errors() -> None:
    robot = Robot.at(Pose(0.0, 0.0, 0.0), DriftModel(turn_bias=0.1), np.random.default_rng(0))
    list(turn_to(robot, math.radians(90.0), LIMITS))
    assert robot.odometry.heading == pytest.approx(math.radians(90.0))
    assert robot.pose.heading == pytest.approx(math.radians(99.0))
