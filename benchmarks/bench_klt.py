"""Timing of KLT-sector homing on the analytic arena (tests/synthetic_panorama.py), one thread.

Prints, for 288- and 720-column panoramas, per-call process CPU time (``time.process_time``),
wall time and the ratio to a floor measured in the same process (bare
``cv2.calcOpticalFlowPyrLK`` forward + backward on the same two images and corners, the
tracker's window, levels and criteria; target: a tracking step within 1.3x) of: corner
detection (describe) per view, one tracking step per image pair, tracking along a route of N
steps, and home (tracking + ordering filter + sector law) for a direct pair and for a route,
each with an empty route cache; and the load average before and after. Then one job: the goal
against every other position of a 6 x 9 grid (15 cm apart, routes 0.5 grid units apart as the
engine makes them), CPU per pair and the tracking steps done against those of tracking every
route from scratch.

Run: ``python benchmarks/bench_klt.py [--repeats N] [--steps N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the arena renderer
from synthetic_panorama import render  # noqa: E402
from timing import as_in_job_workers, cpu_and_wall, load, print_figures  # noqa: E402

from homebench.evaluation.grid_routes import grid_route  # noqa: E402
from homebench.geometry import Grid, PanoramaGeometry, Pose  # noqa: E402
from homebench.methods.klt_sector.method import KltSector  # noqa: E402
from homebench.methods.klt_sector.tracking import KltTracker, Tracks  # noqa: E402

GOAL = Pose(0.2, -0.3, 0.4)
STEP = 0.05  # metres between route views


def bare_lk(
    tracker: KltTracker, before: np.ndarray, after: np.ndarray, corners: np.ndarray
) -> None:
    """The floor of a tracking step: OpenCV's pyramidal LK from ``before`` to ``after`` and
    back (images (h, w) uint8, ``corners`` (n, 2) pixels), with the tracker's parameters."""
    lk = {
        "winSize": (tracker.window_size, tracker.window_size),
        "maxLevel": tracker.pyramid_levels,
        "criteria": (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, 0.01),
        "minEigThreshold": tracker.min_eigen,
    }
    points = np.asarray(corners, dtype=np.float32).reshape(-1, 1, 2)
    moved, _, _ = cv2.calcOpticalFlowPyrLK(before, after, points, None, **lk)
    cv2.calcOpticalFlowPyrLK(after, before, moved, None, **lk)


def run(width: int, steps: int, repeats: int) -> None:
    geometry = PanoramaGeometry.square_pixels(width, math.radians(30.0), math.radians(-30.0))
    method = KltSector()
    tracker = method.tracker
    poses = [Pose(GOAL.x + STEP * k, GOAL.y, GOAL.heading + 0.02 * k) for k in range(steps + 1)]
    views = [render(pose, geometry) for pose in poses]
    features = [method.describe(view) for view in views]
    goal, current, route = features[0], features[-1], features[1:-1]
    tracks = Tracks.start(goal.corners)

    def track_route() -> Tracks:
        t = tracks
        for before, after in zip(features, features[1:], strict=False):
            t = tracker.step(before.image, t, after.image, replenish=False).survivors()
        return t

    survivors = track_route()
    figures = {
        "floor: bare LK forward + backward": cpu_and_wall(
            lambda: bare_lk(tracker, goal.image, features[1].image, goal.corners), repeats * 4
        ),
        "describe (per view)": cpu_and_wall(lambda: method.describe(views[0]), repeats),
        "track step (per image pair)": cpu_and_wall(
            lambda: tracker.step(goal.image, tracks, features[1].image, replenish=False),
            repeats * 4,
        ),
        f"track route ({steps} steps)": cpu_and_wall(track_route, repeats),
        "home, direct pair (1 step)": cpu_and_wall(
            lambda: KltSector().home(features[1], goal), repeats * 4
        ),
        f"home, route ({steps} steps)": cpu_and_wall(
            lambda: KltSector().home(current, goal, route), repeats
        ),
    }
    print(
        f"\n{width} x {geometry.height} panorama: {len(goal.corners)} corners, "
        f"{len(survivors)} survive {steps} steps of {100 * STEP:.0f} cm"
    )
    print_figures(figures, "floor: bare LK forward + backward")


def job(width: int) -> None:
    """One goal against every other position of a grid, routes as the engine gives them."""
    geometry = PanoramaGeometry.square_pixels(width, math.radians(30.0), math.radians(-30.0))
    grid = Grid((6, 9), 0.15, origin=(-0.4, -0.6))
    method = KltSector()
    cells = [(i, j) for i in range(6) for j in range(9)]
    features = {}
    for i, j in cells:
        x, y = grid.position(i, j)
        features[i, j] = method.describe(render(Pose(float(x), float(y), 0.4), geometry))
    goal = (3, 4)
    routes = {ij: grid_route(grid, goal, ij, method.route_step) for ij in cells if ij != goal}
    scratch = sum(len(route) + 1 for route in routes.values())
    before = len({(*route[:k],) for route in routes.values() for k in range(1, len(route) + 1)})

    def one_job() -> KltSector:
        fresh = KltSector()  # an empty route cache, as a job starts
        for ij, route in routes.items():
            fresh.home(features[ij], features[goal], [features[n] for n in route])
        return fresh

    cpu, wall = cpu_and_wall(one_job, 1)
    print(
        f"\njob, {width} columns: goal {goal} against {len(routes)} positions of a 6 x 9 grid: "
        f"{1000 * cpu / len(routes):.2f} ms CPU, {1000 * wall / len(routes):.2f} ms wall per pair; "
        f"{len(one_job()._route_tracks)} tracking steps (every route from scratch: {scratch}; "
        f"with route prefixes only kept: {before + len(routes)})"
    )


def main() -> None:
    as_in_job_workers()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=20)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print(load())
    for width in (288, 720):
        run(width, args.steps, args.repeats)
    job(288)
    print(load())


if __name__ == "__main__":
    main()
