"""Timing of KLT-sector homing on the analytic arena (tests/synthetic_panorama.py), one thread.

Prints, for 288- and 720-column panoramas: corner detection (describe) per view, one tracking
step per image pair (forward + backward LK, prealignment), tracking along a route of N steps,
and home (tracking + ordering filter + sector law) for a direct pair and for a route.

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

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the arena renderer
from synthetic_panorama import render  # noqa: E402
from timing import per_call  # noqa: E402

from homebench.geometry import PanoramaGeometry, Pose  # noqa: E402
from homebench.methods.klt_sector import KltSector  # noqa: E402
from homebench.methods.klt_tracking import Tracks  # noqa: E402

GOAL = Pose(0.2, -0.3, 0.4)
STEP = 0.05  # metres between route views


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
        "describe (per view)": per_call(lambda: method.describe(views[0]), repeats),
        "track step (per image pair)": per_call(
            lambda: tracker.step(goal.image, tracks, features[1].image, replenish=False), repeats
        ),
        f"track route ({steps} steps)": per_call(track_route, repeats),
        "home, direct pair (1 step)": per_call(lambda: method.home(features[1], goal), repeats),
        f"home, route ({steps} steps)": per_call(
            lambda: method.home(current, goal, route), repeats
        ),
    }
    print(
        f"\n{width} x {geometry.height} panorama: {len(goal.corners)} corners, "
        f"{len(survivors)} survive {steps} steps of {100 * STEP:.0f} cm"
    )
    for label, seconds in figures.items():
        print(f"  {label:<30} {1000 * seconds:8.2f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=20)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    for width in (288, 720):
        run(width, args.steps, args.repeats)


if __name__ == "__main__":
    main()
