"""Route homing with any pairwise method: leg by leg from snapshot to snapshot.

The targets are the snapshots stored on the way out (:mod:`~.snapshots`), visited backwards to
home. At each step of a leg the robot takes its view (the scene's camera), asks the method for
the home direction towards the target snapshot (``describe`` both views, ``home``), turns by at
most the turn limit and steps ``step_length`` (:func:`~homebench.experiments.robot.steer`: a
step that must turn further than the limit only turns).

**Arrival** (when the robot switches to the next snapshot), an option of :class:`Arrival`:

- ``minimum`` (default): what the robot sees. The view distance to the target
  (:func:`~.snapshots.view_distance`, independent of the heading) falls as the robot nears the
  snapshot's place and rises once it has passed it (Zeil et al. 2003). The leg ends when the
  distance has not fallen below its best value (by more than ``min_decrease``, relative) for
  ``patience`` forward steps: the robot has passed the minimum. Steps that only turn do not
  count (a turn on the spot leaves the distance as it is).
- ``oracle``: the true position within ``radius_m`` of the snapshot's, a pose oracle for
  comparisons, never the default.

On the home leg the robot then drives back by odometry to where the view distance was smallest
(``return_to_best``, with ``minimum``; a few steps, over which the odometry error is small),
and turns by the method's rotation estimate there, if it gives one (``align``), to face its
starting heading.

A step where the method gives no direction drives straight on (the last command's heading, as
a controller that keeps its last command); ``max_no_estimate`` of them in a row end the leg as
``lost``. ``max_turn_only`` steps in a row that only turn (a direction that keeps jumping past
the robot's turn limit: two places the memory finds about as familiar, one each side) end it
as ``turning`` (default: as many as make a full turn on the spot). A leg gives up after
``max_leg_steps`` steps; a pose the scene cannot show ends the run as ``collision`` (inside an
object, through the room's walls) or ``outside`` (beyond a database's grid or a recording's
reach, where the robot sees nothing: :class:`~homebench.data.synth.world.PoseError`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from homebench.data.synth.world import PoseError, PoseFault
from homebench.experiments.homing import MethodHomer
from homebench.experiments.robot import MotionLimits, Robot, drive_to, steer, turn_to
from homebench.experiments.route.snapshots import SnapshotRule, view_distance
from homebench.geometry import Pose
from homebench.methods.base import HomingEstimate

LegStatus = Literal["reached", "lost", "steps", "turning", "collision", "outside"]
#: The robot's eyes: the unfolded panorama at a pose as frame k (the scene's camera).
Look = Callable[[Pose, int], NDArray[np.uint8]]
#: What steers a leg: the estimate from the grey view seen at a true pose.
Steer = Callable[[Pose, NDArray[np.uint8]], HomingEstimate]


class Arrival(BaseModel):
    """When a leg's target counts as reached: ``criterion`` ``minimum`` (``patience`` forward
    steps without a new smallest view distance, ``min_decrease`` relative) or ``oracle``
    (within ``radius_m`` of the target's true position); each reads its own fields only."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    # minimum: the view distance has passed its minimum; oracle: the true position is near
    criterion: Literal["minimum", "oracle"] = "minimum"
    patience: int = Field(2, ge=1)  # minimum: forward steps without a new smallest distance
    # minimum: a distance is a new smallest only below best x (1 - min_decrease)
    min_decrease: float = Field(0.0, ge=0, lt=1)
    radius_m: float = Field(0.05, gt=0)  # oracle: metres from the target's true position


class FollowParams(BaseModel):
    """What every route follower shares: the ``arrival`` criterion, ``max_no_estimate`` (steps
    without a direction in a row before a leg is lost), ``max_turn_only`` (steps that only
    turn, in a row, before it ends as turning; None: a full turn's worth at the turn limit),
    ``return_to_best`` and ``align`` at home (see the module docstring)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    arrival: Arrival = Arrival()  # when a leg's target counts as reached
    max_no_estimate: int = Field(5, ge=1)  # steps in a row without a direction: leg lost
    # steps in a row that only turn: the leg ends as turning; None: a full turn's worth
    max_turn_only: int | None = Field(None, ge=1)
    # at home (minimum arrival): drive back by odometry to where the view distance was least
    return_to_best: bool = True
    align: bool = True  # at home: turn by the method's rotation estimate against home's view

    def turn_only_limit(self, limits: MotionLimits) -> int:
        """Steps that only turn, in a row, that end a leg: ``max_turn_only`` or a full turn."""
        if self.max_turn_only is not None:
            return self.max_turn_only
        return math.ceil(360.0 / limits.max_turn_deg)


class PairwiseParams(FollowParams):
    """Route homing with a pairwise method: the ``snapshots`` rule, ``max_leg_steps`` and the
    follower's parameters (:class:`FollowParams`)."""

    snapshots: SnapshotRule = SnapshotRule()  # where the outbound snapshots are stored
    max_leg_steps: int = Field(200, ge=1)  # steps after which a leg gives up


@dataclass(frozen=True)
class Target:
    """A snapshot to home to: its outbound ``frame``, the ``image`` (rows, columns) uint8 for
    the view distance, the ``homer`` (the method with its features of it and the entry's
    compass) and its true ``pose`` (for the oracle, a true compass and the records)."""

    frame: int
    image: NDArray[np.uint8]
    homer: MethodHomer
    pose: Pose


@dataclass(frozen=True)
class PairwiseLeg:
    """One leg: ``target`` frame, ``steps`` taken (turns included), steps ``without`` a
    direction, the view distance at the start (``distance_start``) and its smallest value
    (``distance_best``), ``status``, and the true distance to the target's place at the end
    (``miss_m``, metres)."""

    target: int
    steps: int
    without: int
    distance_start: float
    distance_best: float
    status: LegStatus
    miss_m: float


@dataclass
class PairwiseHoming:
    """The homing run: true ``poses`` (the start first), the ``legs``."""

    poses: list[Pose] = field(default_factory=list)
    legs: list[PairwiseLeg] = field(default_factory=list)

    @property
    def status(self) -> LegStatus:
        return self.legs[-1].status if self.legs else "reached"

    def legs_as_dicts(self) -> list[dict[str, Any]]:
        return [asdict(leg) for leg in self.legs]


def grey(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """A panorama (rows, columns) or (rows, columns, 3) as grey levels (rows, columns)."""
    return image if image.ndim == 2 else np.mean(image, axis=2).astype(np.uint8)


class LegRun:
    """The running state of one leg: steps, the best view distance and where it was seen."""

    def __init__(self, target: Target, robot: Robot) -> None:
        self.target, self.steps, self.without, self.since_best = target, 0, 0, 0
        self.start = self.best = math.inf
        self.last = math.nan
        self.best_odometry = robot.odometry

    def saw(self, distance: float, robot: Robot, moved: bool, arrival: Arrival) -> bool:
        """Record the view distance at the robot's pose; True when the target is reached. A
        step that leaves the distance exactly as it was does not count towards the patience:
        the view did not change (a replayed recording shows one image until another is
        nearer), so the robot has not seen itself pass the minimum."""
        if not math.isfinite(self.start):
            self.start = distance
        if distance < self.best * (1.0 - arrival.min_decrease) or not math.isfinite(self.best):
            self.best, self.best_odometry, self.since_best = distance, robot.odometry, 0
        elif moved and distance != self.last:
            self.since_best += 1
        self.last = distance
        if arrival.criterion == "oracle":
            return math.dist(robot.pose.xy, self.target.pose.xy) <= arrival.radius_m
        return self.since_best >= arrival.patience

    def result(self, status: LegStatus, robot: Robot) -> PairwiseLeg:
        miss = math.dist(robot.pose.xy, self.target.pose.xy)
        return PairwiseLeg(
            self.target.frame, self.steps, self.without, self.start, self.best, status, miss
        )


def take_view(look: Look, robot: Robot, result: PairwiseHoming) -> NDArray[np.uint8] | PoseFault:
    """The robot's grey view at its pose as the next frame, or, where the scene cannot show
    it, why ("collision" or "outside")."""
    try:
        return grey(look(robot.pose, len(result.poses) - 1))
    except PoseError as error:
        return error.fault


def drive_leg(
    robot: Robot,
    leg: LegRun,
    steer_by: Steer,
    look: Look,
    limits: MotionLimits,
    params: FollowParams,
    max_steps: int,
    result: PairwiseHoming,
    image: NDArray[np.uint8] | PoseFault,
    may_arrive: Callable[[Robot], bool] = lambda robot: True,
) -> tuple[LegStatus, NDArray[np.uint8] | PoseFault]:
    """Steer by ``steer_by`` towards ``leg``'s target until it is reached, lost, out of steps,
    turning on the spot or out of what the scene shows; its status and the last view (or
    why there is none). Arrival is watched only at poses where ``may_arrive`` (the view
    distances before do not count). ``image``: the view at the robot's pose; poses go to
    ``result``."""
    moved, turning, turn_only = False, 0, params.turn_only_limit(limits)
    while True:
        if isinstance(image, str):
            return image, image
        distance = view_distance(image, leg.target.image) if may_arrive(robot) else None
        if distance is not None and leg.saw(distance, robot, moved, params.arrival):
            return "reached", image
        if leg.steps == max_steps:
            return "steps", image
        if turning == turn_only:
            return "turning", image
        estimate = steer_by(robot.pose, image)
        if estimate.angle is None:
            leg.without += 1
            if leg.without >= params.max_no_estimate:
                return "lost", image
            direction = 0.0
        else:
            leg.without, direction = 0, float(estimate.angle)
        command = steer(direction, limits.step_length, limits)
        robot.execute(command)
        moved, leg.steps = command.forward > 0, leg.steps + 1
        turning = 0 if moved else turning + 1
        result.poses.append(robot.pose)
        image = take_view(look, robot, result)


def home_pairwise(
    robot: Robot,
    targets: list[Target],
    look: Look,
    limits: MotionLimits,
    params: PairwiseParams,
) -> PairwiseHoming:
    """Home from the robot's pose through ``targets`` (visiting order, home last) with the
    targets' homers (a pairwise method each); ``look`` frames numbered from 0."""
    result = PairwiseHoming([robot.pose])
    image = take_view(look, robot, result)
    for k, target in enumerate(targets):
        leg = LegRun(target, robot)
        steer_by = target.homer.estimate
        status, image = drive_leg(
            robot, leg, steer_by, look, limits, params, params.max_leg_steps, result, image
        )
        if status == "reached" and k == len(targets) - 1:
            settle(robot, leg, look, limits, params, result)
        result.legs.append(leg.result(status, robot))
        if status != "reached":
            return result
    return result


def settle(
    robot: Robot,
    leg: LegRun,
    look: Look,
    limits: MotionLimits,
    params: FollowParams,
    result: PairwiseHoming,
) -> None:
    """At home: back to the best view's odometry pose, then turn by the rotation estimate."""
    if params.return_to_best and params.arrival.criterion == "minimum":
        best = leg.best_odometry
        for _ in drive_to(robot, (best.x, best.y), limits, by_odometry=True):
            result.poses.append(robot.pose)
    image = take_view(look, robot, result) if params.align else None
    if image is None or isinstance(image, str):
        return
    estimate = leg.target.homer.estimate(robot.pose, image)
    if estimate.rotation is not None:
        for _ in turn_to(robot, robot.odometry.heading - estimate.rotation, limits):
            result.poses.append(robot.pose)
