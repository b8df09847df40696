"""Timing of route homing (seed 000) in a generated world, one thread.

Prints: render time per frame (the world renders raw and unfolded images), tracking time per
outbound step (KLT with replenishment), per homing step (sector law, and the anchor match
against the target's panorama), and per route: the outbound drive and the visual homing.

Run: ``python benchmarks/bench_route.py [--length M] [--width PX]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from itertools import pairwise  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from homebench.data.synth.spec import UnfoldedImageSpec, WorldSpec  # noqa: E402
from homebench.experiments.robot import DriftModel, MotionLimits, Robot  # noqa: E402
from homebench.experiments.route.lifecycle import select_targets  # noqa: E402
from homebench.experiments.route.outbound import drive_outbound  # noqa: E402
from homebench.experiments.route.visual import VisualHomingParams, home_visually  # noqa: E402
from homebench.experiments.scene import Camera, world_scene  # noqa: E402
from homebench.geometry import Pose  # noqa: E402
from homebench.methods.klt_tracking import KltTracker, Tracks  # noqa: E402

HOME = Pose(1.7, 1.8, math.pi / 2)


class TimedCamera:
    """A camera that adds up its wall time and calls."""

    def __init__(self, camera: Camera):
        self.camera, self.seconds, self.calls = camera, 0.0, 0

    def __call__(self, pose: Pose, k: int) -> np.ndarray:
        start = time.perf_counter()
        image = self.camera(pose, k)
        self.seconds += time.perf_counter() - start
        self.calls += 1
        return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=2.0, help="route length, metres")
    parser.add_argument("--width", type=int, default=360, help="panorama width, pixels")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    scene = world_scene(WorldSpec(unfolded=UnfoldedImageSpec(width=args.width)))
    limits = MotionLimits(step_length=0.05, max_turn_deg=10.0)
    tracker = KltTracker(max_corners=150, min_tracks=100, min_eigen=0.02)
    waypoints = np.array([[HOME.x, HOME.y], [HOME.x, HOME.y + args.length]])
    robot = Robot.at(HOME, DriftModel(), np.random.default_rng(0))

    camera = TimedCamera(scene.camera(0, "outbound"))
    start = time.perf_counter()
    outbound = drive_outbound(robot, waypoints, limits, camera, tracker)
    outbound_s = time.perf_counter() - start
    render_ms = 1000 * camera.seconds / camera.calls
    start = time.perf_counter()  # the outbound's tracking again, without rendering
    tracks = Tracks.start(tracker.detect(outbound.images[0]))
    for before, after in pairwise(outbound.images):
        tracks = tracker.step(before, tracks, after).survivors()
    track_ms = 1000 * (time.perf_counter() - start) / outbound.end
    targets = select_targets(outbound.log.lifecycles(), outbound.end, 80)

    camera = TimedCamera(scene.camera(0, "homing"))
    params = VisualHomingParams(anchor=True)
    start = time.perf_counter()
    homing = home_visually(
        robot, outbound, targets, camera, tracker, scene.geometry, limits, params
    )
    homing_s = time.perf_counter() - start
    steps = len(homing.poses) - 1
    homing_ms = 1000 * (homing_s - camera.seconds) / max(steps, 1)

    print(f"panorama {scene.geometry.width} x {scene.geometry.height} px")
    print(f"render per frame (raw + unfolded): {render_ms:.1f} ms")
    print(f"outbound: {len(outbound.images)} frames, {args.length:g} m, {outbound_s:.2f} s")
    print(f"  tracking per step (KLT, replenishing): {track_ms:.1f} ms")
    print(f"homing: {steps} steps, {len(targets) - 1} intermediate positions, {homing_s:.2f} s")
    print(f"  per step without rendering (KLT + anchor + sector law): {homing_ms:.1f} ms")
    total = outbound_s + homing_s
    print(f"route: {total:.2f} s, {total / args.length:.2f} s per metre of route")


if __name__ == "__main__":
    main()
