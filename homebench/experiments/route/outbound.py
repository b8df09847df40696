"""The outbound journey of route homing: drive a route of waypoints, track corners, log them.

The robot is driven along the route as the paper's was (by an operator who sees where it is):
the steering uses the true pose, the true motion carries the motion noise, and the odometry
integrates the commands. A panorama is taken at the start and after every step; corners are
detected at home and tracked frame to frame, new ones detected when too few survive, and every
frame's features go into a :class:`~homebench.experiments.route.lifecycle.FeatureLog` (Fig. 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.experiments.robot import MotionLimits, Robot, drive_to
from homebench.experiments.route.lifecycle import FeatureLog
from homebench.experiments.scene import Camera
from homebench.geometry import FloatArray, Pose
from homebench.methods.klt_sector.tracking import KltTracker, Tracks

#: A waypoint counts as reached within this fraction of a step (a driver's precision).
WAYPOINT_TOLERANCE = 0.2


def route_prefix(waypoints: ArrayLike, length: float) -> FloatArray:
    """The first ``length`` metres of the polyline ``waypoints`` (k, 2), as waypoints (m, 2).

    Raises ValueError if the polyline is shorter than ``length``.
    """
    points = np.asarray(waypoints, dtype=np.float64).reshape(-1, 2)
    segments = np.hypot(*np.diff(points, axis=0).T)
    ends = np.cumsum(segments)
    if length > ends[-1] + 1e-9:
        raise ValueError(f"the route is {ends[-1]:.3f} m long, shorter than {length} m")
    k = int(np.searchsorted(ends, length - 1e-12))
    start = ends[k] - segments[k]
    fraction = (length - start) / segments[k]
    cut = points[k] + fraction * (points[k + 1] - points[k])
    return np.vstack([points[: k + 1], cut[None]])


def path_length(poses: ArrayLike) -> float:
    """Length in metres of the path through poses (n, >= 2) (x, y first)."""
    xy = np.asarray(poses, dtype=np.float64)[:, :2]
    return float(np.sum(np.hypot(*np.diff(xy, axis=0).T)))


def as_array(poses: list[Pose]) -> FloatArray:
    """Poses as rows (x, y, heading); shape (n, 3)."""
    return np.array([(p.x, p.y, p.heading) for p in poses], dtype=np.float64).reshape(-1, 3)


@dataclass(frozen=True)
class Outbound:
    """The recorded route: ``poses`` and ``odometry`` (n, 3), one panorama per frame, the log."""

    poses: FloatArray
    odometry: FloatArray
    images: list[NDArray[np.uint8]]
    log: FeatureLog

    @property
    def end(self) -> int:
        """Index of the last frame."""
        return len(self.images) - 1


def drive_route(
    robot: Robot, waypoints: ArrayLike, limits: MotionLimits
) -> tuple[FloatArray, FloatArray]:
    """Drive from the robot's pose through ``waypoints[1:]`` (k, 2): the true poses and the
    odometry poses (n, 3), the start first, one row per step (a frame)."""
    poses, belief = [robot.pose], [robot.odometry]
    tolerance = WAYPOINT_TOLERANCE * limits.step_length
    for target in np.asarray(waypoints, dtype=np.float64)[1:]:
        xy = (float(target[0]), float(target[1]))
        for _ in drive_to(robot, xy, limits, by_odometry=False, tolerance=tolerance):
            poses.append(robot.pose)
            belief.append(robot.odometry)
    return as_array(poses), as_array(belief)


def as_pose(row: ArrayLike) -> Pose:
    """A pose row (x, y, heading) as a :class:`Pose`."""
    x, y, heading = (float(v) for v in np.asarray(row, dtype=np.float64))
    return Pose(x, y, heading)


def drive_outbound(
    robot: Robot,
    waypoints: ArrayLike,
    limits: MotionLimits,
    camera: Camera,
    tracker: KltTracker,
) -> Outbound:
    """Drive from the robot's pose through ``waypoints[1:]`` (k, 2), tracking corners."""
    poses, belief = drive_route(robot, waypoints, limits)
    images = [camera(as_pose(poses[0]), 0)]
    tracks = Tracks.start(tracker.detect(images[0]))
    log = FeatureLog()
    log.record(tracks)
    for k, pose in enumerate(poses[1:], start=1):
        image = camera(as_pose(pose), k)
        tracks = tracker.step(images[-1], tracks, image, replenish=True).survivors()
        log.record(tracks)
        images.append(image)
    return Outbound(poses, belief, images, log)
