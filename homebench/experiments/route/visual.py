"""Visual route homing (seed 000, 2.1 and 2.3): leg by leg with the sector law.

For each leg, from the previous target frame ``c`` (the route's end at first) to the next target
``t`` (see :func:`~.lifecycle.select_targets`), the features are those alive
through frames ``t .. c`` of the outbound log: their positions in frame ``t`` are the goal
bearings. At the start of a leg the robot is near the place of frame ``c`` but not at its
heading; the **pose correction** estimates the heading change ``phi`` since frame ``c`` as the
median angular shift of the previous leg's features, turns frame ``c``'s panorama by ``phi``
(whole columns) and looks for the leg's features around their predicted places with KLT (the
paper's "feature selection in small windows centred at the predicted locations").

Then the robot steps along the sector law's motion vector M (robot frame), tracking the
features frame to frame, until ``|M|`` falls below ``goal_threshold`` (the paper's stop test).
Step length: ``gain * |M|`` metres, at most the limit: |M| shrinks in proportion to the
distance left, so the steps shrink as the target nears (about pi x distance / scene depth).
At home, the robot turns back by the last ``phi`` to face its starting heading.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

import cv2
import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from homebench.data.synth.world import PoseError
from homebench.experiments.robot import MotionLimits, Robot, steer, turn_to
from homebench.experiments.route.lifecycle import IntArray, shared_ids
from homebench.experiments.route.outbound import Outbound
from homebench.experiments.route.pairwise import LegStatus
from homebench.experiments.scene import Camera
from homebench.geometry import PanoramaGeometry, Pose, wrap_angle
from homebench.methods.klt_sector.sector_law import (
    MIN_FEATURES,
    bearings,
    goal_reached,
    heading_change,
    motion_vector,
    order_filter,
)
from homebench.methods.klt_sector.tracking import KltTracker, Tracks


class VisualHomingParams(BaseModel):
    """``min_shared``: the paper's K; ``goal_threshold`` (rad): stop when |M| is below it;
    ``gain`` (m/rad): step length per unit |M|; ``min_features``: fewest kept features a step
    needs; ``max_leg_steps``: steps after which a leg gives up; ``bisectors``: see
    :mod:`homebench.methods.klt_sector.sector_law`; ``anchor`` (a departure, off by default): after
    each
    frame-to-frame step, look for the features again from the target's own panorama and keep
    those whose patches correlate at least ``anchor_similarity`` (see :func:`anchor`)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    # the paper's K: features a target frame shares with the previous one (paper's run: 80)
    min_shared: int = Field(80, ge=MIN_FEATURES)
    goal_threshold: float = Field(0.01, gt=0)  # a leg ends when |M| falls below this, radians
    gain: float = Field(0.5, gt=0)  # step length per unit |M|, m/rad (at most the step limit)
    min_features: int = Field(MIN_FEATURES, ge=MIN_FEATURES)  # fewest kept features a step needs
    max_leg_steps: int = Field(400, ge=1)  # steps after which a leg gives up
    # sector bisectors: the current view's (no compass needed) or the goal view's, turned
    bisectors: Literal["current", "goal"] = "current"
    anchor: bool = False  # a departure: re-find the features from the target's panorama
    # least correlation of a feature's target and current patches for anchor to keep it
    anchor_similarity: float = Field(0.9, ge=-1, le=1)


@dataclass(frozen=True)
class Leg:
    """One leg: ``target`` frame, features it started with (``shared`` in the log, ``found``
    again by the pose correction), ``steps`` taken, features kept and ``|M|`` at its last
    frame, ``status``, and the heading change since the target's frame estimated there
    (``phi``, rad) beside the true one (``phi_true``)."""

    target: int
    shared: int
    found: int
    steps: int
    kept: int
    motion: float
    status: LegStatus
    phi: float
    phi_true: float


@dataclass
class VisualHoming:
    """The homing run: true ``poses`` (the start first), the ``legs``, the overall ``status``."""

    poses: list[Pose] = field(default_factory=list)
    legs: list[Leg] = field(default_factory=list)

    @property
    def status(self) -> LegStatus:
        return self.legs[-1].status if self.legs else "reached"

    def legs_as_dicts(self) -> list[dict[str, Any]]:
        return [asdict(leg) for leg in self.legs]


def refind(
    tracker: KltTracker,
    before: NDArray[np.uint8],
    ids: IntArray,
    positions: NDArray[np.float32],
    image: NDArray[np.uint8],
    phi: float,
    geometry: PanoramaGeometry,
) -> Tracks:
    """Features at ``positions`` (n, 2) in ``before``, found again in ``image`` taken at the same
    place after a heading change ``phi`` (rad, ccw): ``before`` and the positions are turned by
    ``phi`` (whole columns), then KLT refines them. Returns the survivors."""
    shift = round(geometry.columns_for_rotation(phi))
    turned = positions.astype(np.float32).copy()
    turned[:, 0] = (turned[:, 0] + shift) % geometry.width
    start = Tracks(ids, turned, np.ones(len(ids), dtype=bool), int(ids.max(initial=-1)) + 1)
    return tracker.step(np.roll(before, shift, axis=1), start, image, replenish=False).survivors()


def patch_similarity(
    first: NDArray[np.uint8],
    at_first: NDArray[np.float32],
    second: NDArray[np.uint8],
    at_second: NDArray[np.float32],
    size: int,
) -> NDArray[np.float64]:
    """Normalised cross-correlation (n,) of ``size`` x ``size`` patches of two panoramas
    centred at ``at_first`` and ``at_second`` (n, 2); columns wrap, rows repeat the border.
    A flat patch correlates 0."""
    pad = size
    wrapped = [np.pad(image, ((0, 0), (pad, pad)), mode="wrap") for image in (first, second)]
    offset = np.float32([pad, 0])
    scores = np.zeros(len(at_first))
    for k, (p, q) in enumerate(zip(at_first + offset, at_second + offset, strict=True)):
        a = cv2.getRectSubPix(wrapped[0], (size, size), (float(p[0]), float(p[1])))
        b = cv2.getRectSubPix(wrapped[1], (size, size), (float(q[0]), float(q[1])))
        a = a.astype(np.float64) - a.mean()
        b = b.astype(np.float64) - b.mean()
        norm = math.sqrt(float(np.sum(a * a) * np.sum(b * b)))
        scores[k] = float(np.sum(a * b)) / norm if norm > 0 else 0.0
    return scores


def anchor(
    tracker: KltTracker,
    goal_image: NDArray[np.uint8],
    goal: Tracks,
    tracks: Tracks,
    image: NDArray[np.uint8],
    min_similarity: float,
) -> Tracks:
    """``tracks`` in ``image``, each position replaced by the one KLT finds from the feature's
    ``goal`` position in ``goal_image`` (``goal``: same rows and ids as ``tracks``) where the
    two patches correlate at least ``min_similarity``.

    Frame-to-frame tracking drifts: its small errors add up along the outbound route and the
    homing run, and where the two runs differ they do not cancel. Matching against the target's
    panorama has no drift, and the closer the robot comes to the target the better it works.
    Far from it the patches differ and KLT may stop anywhere (at its first guess, the goal
    position turned by the global shift, which would make M vanish); the correlation test (the
    "dissimilarity between the initial and the current frame" that Shi and Tomasi monitor)
    keeps the tracked position there.
    """
    direct = tracker.step(goal_image, goal, image, replenish=False)
    similar = patch_similarity(
        goal_image, goal.positions, image, direct.positions, tracker.window_size
    )
    use = direct.alive & (similar >= min_similarity)
    positions = np.where(use[:, None], direct.positions, tracks.positions)
    return Tracks(tracks.ids, positions.astype(np.float32), tracks.alive, tracks.next_id)


def leg_motion(
    tracks: Tracks,
    goal: NDArray[np.float32],
    goal_row: dict[int, int],
    geometry: PanoramaGeometry,
    params: VisualHomingParams,
) -> tuple[NDArray[np.float64] | None, int, float]:
    """The sector law on ``tracks`` against their ``goal`` positions (rows by ``goal_row[id]``).

    Returns M (2,) (None when fewer than ``min_features`` pass the ordering filter), the number
    of kept features and the heading change since the goal view (rad; NaN without M).
    """
    current = bearings(tracks.positions[:, 0], geometry)
    rows = [goal_row[i] for i in tracks.ids.tolist()]
    at_goal = bearings(goal[rows, 0], geometry)
    kept = order_filter(current, at_goal)
    n = int(np.count_nonzero(kept))
    if n < params.min_features:
        return None, n, float("nan")
    motion = motion_vector(current[kept], at_goal[kept], params.bisectors)
    return motion, n, heading_change(current[kept], at_goal[kept])


def _leg_status(
    motion: NDArray[np.float64] | None, steps: int, params: VisualHomingParams
) -> LegStatus | None:
    """Why a leg ends after ``steps`` steps with ``motion`` M, or None while it goes on."""
    if motion is None:
        return "lost"
    if goal_reached(motion, params.goal_threshold):
        return "reached"
    if steps == params.max_leg_steps:
        return "steps"
    return None


def home_visually(
    robot: Robot,
    outbound: Outbound,
    targets: list[int],
    camera: Camera,
    tracker: KltTracker,
    geometry: PanoramaGeometry,
    limits: MotionLimits,
    params: VisualHomingParams,
) -> VisualHoming:
    """Home from the route's end through ``targets`` (frames, 0 last) with the sector law.

    The robot's pose must be the outbound's last pose; ``camera`` frames are numbered from 0.
    At home the robot turns back by the estimated heading change.
    """
    lifecycles = outbound.log.lifecycles()
    result = VisualHoming([robot.pose])
    image = camera(robot.pose, 0)
    previous, phi = outbound.end, 0.0
    for target in targets:
        ids = shared_ids(lifecycles, target, previous)
        before = outbound.log.positions(previous, ids)
        tracks = refind(tracker, outbound.images[previous], ids, before, image, phi, geometry)
        goal = outbound.log.positions(target, ids)
        goal_row = {i: k for k, i in enumerate(ids.tolist())}
        found, steps = len(tracks), 0
        while True:
            motion, kept, phi = leg_motion(tracks, goal, goal_row, geometry, params)
            size = float("nan") if motion is None else float(np.hypot(*motion))
            status = _leg_status(motion, steps, params)
            if status is not None:
                break
            robot.execute(steer(math.atan2(motion[1], motion[0]), params.gain * size, limits))
            steps += 1
            result.poses.append(robot.pose)
            try:
                new_image = camera(robot.pose, len(result.poses) - 1)
            except PoseError as error:
                status = error.fault
                break
            tracks = tracker.step(image, tracks, new_image, replenish=False).survivors()
            if params.anchor:
                rows = [goal_row[i] for i in tracks.ids.tolist()]
                at_goal = Tracks(tracks.ids, goal[rows], tracks.alive, tracks.next_id)
                tracks = anchor(
                    tracker,
                    outbound.images[target],
                    at_goal,
                    tracks,
                    new_image,
                    params.anchor_similarity,
                )
            image = new_image
        phi_true = float(wrap_angle(robot.pose.heading - outbound.poses[target, 2]))
        result.legs.append(Leg(target, len(ids), found, steps, kept, size, status, phi, phi_true))
        if status != "reached":
            return result
        previous = target
    for _ in turn_to(robot, robot.odometry.heading - phi, limits):
        result.poses.append(robot.pose)
    return result
