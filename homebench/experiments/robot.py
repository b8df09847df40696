"""The simulated robot of route homing: commanded steps, motion noise / odometry drift, steering.

A step is a :class:`Motion`: turn on the spot by ``turn`` (radians, ccw), then drive
``forward`` metres straight ahead while the heading drifts by ``drift`` (spread over the
translation: the robot moves along the mean heading, the midpoint rule of an arc).

**Odometry** is the robot's belief: it integrates the commanded steps exactly (wheel encoders
measure what the controller asked for). **The true motion** is the command perturbed by the
:class:`DriftModel`: systematic errors (a distance scale error, a turn scale error and a heading
drift per metre, the wheel-diameter and wheelbase errors of Borenstein's UMBmark) plus random
errors whose variances grow linearly with the distance driven and the angle turned. The gap
between belief and truth is the odometry drift; a zero model gives exact dead reckoning.

Poses use :class:`homebench.geometry.Pose` (world frame, metres, heading in radians).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from homebench.geometry import Pose, angle_diff, home_direction, wrap_angle


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass(frozen=True)
class Motion:
    """One step: ``turn`` (rad, ccw) on the spot, then ``forward`` metres with ``drift`` (rad)."""

    turn: float
    forward: float
    drift: float = 0.0


def apply_motion(pose: Pose, motion: Motion) -> Pose:
    """The pose after ``motion`` from ``pose`` (exact kinematics, no noise)."""
    heading = pose.heading + motion.turn
    mean = heading + motion.drift / 2.0
    return Pose(
        pose.x + motion.forward * math.cos(mean),
        pose.y + motion.forward * math.sin(mean),
        float(wrap_angle(heading + motion.drift)),
    )


class DriftModel(_Frozen):
    """Errors of the true motion against the command (all zero: a perfect robot).

    Random: ``translation_var`` (m^2 per metre driven), ``rotation_var`` (rad^2 of heading per
    metre driven), ``turn_var`` (rad^2 per radian turned). Systematic: ``scale_bias`` (true
    distance = (1 + scale_bias) x commanded), ``turn_bias`` (the same for turns) and
    ``heading_bias`` (rad of ccw heading drift per metre driven).
    """

    translation_var: float = Field(0.0, ge=0)  # random distance error, m^2 per metre driven
    rotation_var: float = Field(0.0, ge=0)  # random heading drift, rad^2 per metre driven
    turn_var: float = Field(0.0, ge=0)  # random turn error, rad^2 per radian turned
    scale_bias: float = Field(0.0, gt=-1)  # true distance = (1 + scale_bias) x commanded
    turn_bias: float = Field(0.0, gt=-1)  # true turn = (1 + turn_bias) x commanded
    heading_bias: float = 0.0  # systematic ccw heading drift, rad per metre driven

    def perturb(self, command: Motion, rng: np.random.Generator) -> Motion:
        """The true motion of ``command``; draws three normals from ``rng`` per call."""
        z = rng.standard_normal(3)
        distance, angle = abs(command.forward), abs(command.turn)
        return Motion(
            turn=command.turn * (1.0 + self.turn_bias) + z[0] * math.sqrt(self.turn_var * angle),
            forward=command.forward * (1.0 + self.scale_bias)
            + z[1] * math.sqrt(self.translation_var * distance),
            drift=command.drift
            + self.heading_bias * distance
            + z[2] * math.sqrt(self.rotation_var * distance),
        )


class MotionLimits(_Frozen):
    """Most the robot moves between two frames: ``step_length`` metres, ``max_turn_deg``.

    At a frame interval dt these are the maximum speeds: step_length / dt and max_turn_deg / dt
    (the paper's robot: at most 4 cm/s and 3 deg/s).
    """

    step_length: float = Field(0.05, gt=0)  # most the robot drives in one frame, metres
    max_turn_deg: float = Field(10.0, gt=0, le=180)  # most it turns in one frame, degrees

    @property
    def max_turn(self) -> float:
        return math.radians(self.max_turn_deg)


def steer(direction: float, distance: float, limits: MotionLimits) -> Motion:
    """The step towards ``direction`` (robot frame, rad) for at most ``distance`` metres.

    A differential-drive robot: it turns on the spot, as far as the limit allows, until the
    direction lies within one turn; that step it turns onto it and drives straight. (Driving
    part of a step while still turning makes arcs whose radius, at a slow turn rate, exceeds
    the distance left: the robot then circles its target.) A direction within one turn of
    straight behind is turned to counter-clockwise: its wrapped sign would flip from frame to
    frame and the robot would rock on the spot.
    """
    wanted = float(wrap_angle(direction))
    if abs(wanted) > math.pi - limits.max_turn:
        wanted = abs(wanted)
    if abs(wanted) > limits.max_turn:
        return Motion(math.copysign(limits.max_turn, wanted), 0.0)
    return Motion(wanted, min(limits.step_length, max(distance, 0.0)))


@dataclass
class Robot:
    """The true ``pose``, the ``odometry`` belief, the drift model and the noise stream."""

    pose: Pose
    odometry: Pose
    drift: DriftModel
    rng: np.random.Generator

    @classmethod
    def at(cls, pose: Pose, drift: DriftModel, rng: np.random.Generator) -> Robot:
        """A robot whose odometry starts at its true pose."""
        return cls(pose, pose, drift, rng)

    def execute(self, command: Motion) -> None:
        """Odometry integrates ``command``; the true pose moves by its perturbed version."""
        self.odometry = apply_motion(self.odometry, command)
        self.pose = apply_motion(self.pose, self.drift.perturb(command, self.rng))

    def sensed(self, by_odometry: bool) -> Pose:
        """The pose a controller steers by: the belief, or the truth (a human driver's view)."""
        return self.odometry if by_odometry else self.pose


def drive_to(
    robot: Robot,
    target: tuple[float, float],
    limits: MotionLimits,
    *,
    by_odometry: bool,
    tolerance: float = 1e-9,
    max_steps: int = 100_000,
) -> Iterator[Motion]:
    """Steer to ``target`` (x, y) until the sensed pose is within ``tolerance`` metres.

    A generator: executes one step per iteration and yields its command (the caller takes the
    frame). Stops after ``max_steps`` steps at the latest.
    """
    for _ in range(max_steps):
        here = robot.sensed(by_odometry)
        distance = math.dist((here.x, here.y), target)
        if distance <= tolerance:
            return
        direction = float(home_direction(here.xy, target, here.heading))
        command = steer(direction, distance, limits)
        robot.execute(command)
        yield command


def turn_to(robot: Robot, heading: float, limits: MotionLimits) -> Iterator[Motion]:
    """Turn on the spot until the odometry heading is ``heading`` (rad); a step per iteration."""
    while True:
        error = float(angle_diff(heading, robot.odometry.heading))
        if abs(error) <= 1e-12:
            return
        command = Motion(float(np.clip(error, -limits.max_turn, limits.max_turn)), 0.0)
        robot.execute(command)
        yield command


def dead_reckon(robot: Robot, home: Pose, limits: MotionLimits) -> tuple[list[Pose], list[Pose]]:
    """Odometry-based homing: drive to ``home`` and turn to its heading by odometry alone.

    Returns the true poses and the odometry poses, the starting ones first.
    """
    truth, belief = [robot.pose], [robot.odometry]
    for _ in (*drive_to(robot, (home.x, home.y), limits, by_odometry=True),
              *turn_to(robot, home.heading, limits)):  # fmt: skip
        truth.append(robot.pose)
        belief.append(robot.odometry)
    return truth, belief
