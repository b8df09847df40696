"""Timing of route homing (seed 000) in a generated world, one thread.

Prints process CPU and wall time: per rendered frame (the world renders raw and unfolded
images), per outbound tracking step (KLT with replenishment), per homing step without its
rendering (sector law, and the anchor match against the target's panorama), each CPU time over
a floor measured in the same process (OpenCV's pyramidal LK forward and backward on the first
two outbound frames, as ``bench_klt.py``); then per route: the outbound drive and the visual
homing. The load average before and after. The tracker, motion limits and homing parameters
are those of ``configs/klt_route.yaml`` (with the anchor match on), the route a straight line.

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
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from bench_klt import bare_lk  # noqa: E402
from timing import as_in_job_workers, cpu_and_wall, load, print_figures, timed  # noqa: E402

from homebench.data.synth.spec import UnfoldedImageSpec, WorldSpec  # noqa: E402
from homebench.experiments.robot import DriftModel, Robot  # noqa: E402
from homebench.experiments.route.config import load_route_config  # noqa: E402
from homebench.experiments.route.lifecycle import select_targets  # noqa: E402
from homebench.experiments.route.outbound import drive_outbound  # noqa: E402
from homebench.experiments.route.visual import home_visually  # noqa: E402
from homebench.experiments.scene import Camera, world_scene  # noqa: E402
from homebench.geometry import Pose  # noqa: E402
from homebench.methods.klt_sector.tracking import Tracks  # noqa: E402

HOME = Pose(1.7, 1.8, math.pi / 2)
ROOT = Path(__file__).resolve().parents[1]


class TimedCamera:
    """A camera that adds up its process CPU and wall time and its calls."""

    def __init__(self, camera: Camera):
        self.camera, self.cpu, self.wall, self.calls = camera, 0.0, 0.0, 0

    def __call__(self, pose: Pose, k: int) -> np.ndarray:
        cpu, wall = time.process_time(), time.perf_counter()
        image = self.camera(pose, k)
        self.cpu += time.process_time() - cpu
        self.wall += time.perf_counter() - wall
        self.calls += 1
        return image


def main() -> None:
    as_in_job_workers()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=2.0, help="route length, metres")
    parser.add_argument("--width", type=int, default=360, help="panorama width, pixels")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    scene = world_scene(WorldSpec(unfolded=UnfoldedImageSpec(width=args.width)))
    config = load_route_config(ROOT / "configs" / "klt_route.yaml")  # what users run
    limits, tracker = config.motion, config.klt()
    waypoints = np.array([[HOME.x, HOME.y], [HOME.x, HOME.y + args.length]])
    robot = Robot.at(HOME, DriftModel(), np.random.default_rng(0))

    print(load())
    camera = TimedCamera(scene.camera(0, "outbound"))
    outbound, outbound_time = timed(drive_outbound, robot, waypoints, limits, camera, tracker)
    render = (camera.cpu / camera.calls, camera.wall / camera.calls)

    def track_outbound() -> None:  # the outbound's tracking again, without rendering
        tracks = Tracks.start(tracker.detect(outbound.images[0]))
        for before, after in pairwise(outbound.images):
            tracks = tracker.step(before, tracks, after).survivors()

    _, tracked = timed(track_outbound)
    tracking = (tracked[0] / outbound.end, tracked[1] / outbound.end)
    targets = select_targets(outbound.log.lifecycles(), outbound.end, config.homing.min_shared)

    camera = TimedCamera(scene.camera(0, "homing"))
    params = config.homing.model_copy(update={"anchor": True})
    homing, homing_time = timed(
        home_visually, robot, outbound, targets, camera, tracker, scene.geometry, limits, params
    )
    steps = len(homing.poses) - 1
    per_step = (
        (homing_time[0] - camera.cpu) / max(steps, 1),
        (homing_time[1] - camera.wall) / max(steps, 1),
    )
    first, second = outbound.images[:2]
    corners = tracker.detect(first)

    print(f"panorama {scene.geometry.width} x {scene.geometry.height} px")
    floor = f"floor: bare LK forward + backward ({len(corners)} corners)"
    figures = {
        floor: cpu_and_wall(lambda: bare_lk(tracker, first, second, corners), 20),
        "render per frame (raw + unfolded)": render,
        "tracking per outbound step (KLT, replenishing)": tracking,
        "homing step without rendering (KLT + anchor + sector law)": per_step,
    }
    print_figures(figures, floor)
    print(f"outbound: {len(outbound.images)} frames, {args.length:g} m, {_seconds(outbound_time)}")
    print(
        f"homing: {steps} steps, {len(targets) - 1} intermediate positions, {_seconds(homing_time)}"
    )
    total = tuple(o + h for o, h in zip(outbound_time, homing_time, strict=True))
    per_metre = tuple(t / args.length for t in total)
    print(f"route: {_seconds(total)}, per metre of route {_seconds(per_metre)}")
    print(load())


def _seconds(times: tuple[float, ...]) -> str:
    return f"{times[0]:.2f} s CPU, {times[1]:.2f} s wall"


if __name__ == "__main__":
    main()
