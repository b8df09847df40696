"""Timing of the sift method on rendered raw 752 x 564 images, one thread.

Prints process CPU and wall time per call, each CPU time over a floor measured in the same
process: ``describe`` per raw image against the bare OpenCV SIFT call it makes (same
parameters and annulus mask), and ``home`` per pair with cached features (P: with mismatch
elimination, PN: without) and the descriptor matching against ``cv2.BFMatcher.knnMatch`` with
k = 2 (the matching alone is checked to give the same matches as the matcher with the ratio
test). Then the triple solver against a per-triple Python loop kept here (the same closed
form, one triple at a time, then eq. 5's search over alpha-bar on a 0.01 deg grid), checked to
give the same answer. Targets: ``home`` under 10 ms per pair with a few hundred matches,
``describe`` under 150 ms per image. The load average is printed before and after.

Run: ``python benchmarks/bench_sift.py [--repeats N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from timing import as_in_job_workers, cpu_and_wall, load, print_figures  # noqa: E402

from homebench.data.synth.spec import WorldSpec  # noqa: E402
from homebench.data.synth.world import build_world  # noqa: E402
from homebench.geometry import Pose, angle_diff, wrap_angle  # noqa: E402
from homebench.methods.base import View  # noqa: E402
from homebench.methods.sift.matching import match_descriptors  # noqa: E402
from homebench.methods.sift.method import Sift, SiftFeatures, annulus_mask  # noqa: E402
from homebench.methods.sift.solver import (  # noqa: E402
    choose_triples,
    circular_least_squares,
    solve_triples,
)

SPEC = WorldSpec(seed=0, grid={"shape": [5, 5]})


def _views() -> tuple[View, View]:
    """Current and goal raw views 0.6 m apart, the robot turned by 1 rad."""
    world = build_world(SPEC)
    x, y = SPEC.to_grid().position(2, 2)
    geometry = SPEC.raw.geometry()
    current = world.render(Pose(x + 0.6, y - 0.3, 1.0), noise_seed=1)["raw"]
    goal = world.render(Pose(x, y, 0.0), noise_seed=2)["raw"]
    return View(current, geometry), View(goal, geometry)


def solve_one_triple(theta: tuple[float, ...], theta_p: tuple[float, ...]) -> tuple[float, float]:
    """Reference: eq. 3's closed form for one triple, scalar maths; (alpha, psi) or NaNs."""
    delta = [tp - t for t, tp in zip(theta, theta_p, strict=True)]
    w = [math.sin(theta_p[(i + 2) % 3] - theta_p[(i + 1) % 3]) for i in range(3)]
    p = sum(wi * math.cos(d) for wi, d in zip(w, delta, strict=True))
    q = sum(wi * math.sin(d) for wi, d in zip(w, delta, strict=True))
    psi = math.atan2(-q, p)
    rows = np.array([[math.sin(tp + psi), -math.cos(tp + psi)] for tp in theta_p])
    rhs = np.array([math.sin(psi + d) for d in delta])
    (a, b), *_ = np.linalg.lstsq(rows, rhs, rcond=None)
    ahead = [
        math.cos(psi + d) - (a * math.cos(tp + psi) + b * math.sin(tp + psi))
        for d, tp in zip(delta, theta_p, strict=True)
    ]
    if sum(ahead) < 0:
        psi, ahead = psi + math.pi, [-s for s in ahead]
    if math.hypot(p, q) <= 1e-12 or min(ahead) <= 0:
        return math.nan, math.nan
    return math.atan2(b, a), float(wrap_angle(psi))


def grid_least_squares(angles: np.ndarray, step_deg: float = 0.01) -> float:
    """Reference: eq. 5-6 by a search over alpha-bar in [-pi, pi) on a grid."""
    grid = np.radians(np.arange(-180.0, 180.0, step_deg))
    ssd = [np.sum(angle_diff(angles, m) ** 2) for m in grid]
    return float(grid[int(np.argmin(ssd))])


def bench_solver(theta: np.ndarray, theta_p: np.ndarray, max_triples: int, repeats: int) -> None:
    triples = choose_triples(len(theta), max_triples, np.random.default_rng(0))

    def vectorised() -> tuple[float, float]:
        s = solve_triples(theta, theta_p, triples, ahead_filter=True)  # as the reference
        alpha = circular_least_squares(s.alpha[s.valid])[0]
        return alpha, circular_least_squares(s.psi[s.valid])[0]

    def reference() -> tuple[float, float]:
        solved = np.array([solve_one_triple(tuple(theta[t]), tuple(theta_p[t])) for t in triples])
        solved = solved[~np.isnan(solved[:, 0])]
        return grid_least_squares(solved[:, 0]), grid_least_squares(solved[:, 1])

    fast, slow = vectorised(), reference()
    agree = max(abs(float(angle_diff(f, s))) for f, s in zip(fast, slow, strict=True))
    loop = f"reference: per-triple loop + grid, {len(triples)} triples"
    figures = {
        loop: cpu_and_wall(reference, 1),
        "solver (vectorised)": cpu_and_wall(vectorised, repeats),
    }
    print_figures(figures, loop)
    speed_up = figures[loop][0] / figures["solver (vectorised)"][0]
    print(f"  speed-up {speed_up:.0f}x; alpha and psi agree to {math.degrees(agree):.3f} deg")


def bench_describe(view: View, method: Sift, repeats: int) -> None:
    """``describe`` against the bare OpenCV call it makes."""
    mask = annulus_mask(view.geometry) if method.mask_annulus else None
    detector = method._detector()
    floor = "floor: bare cv2 SIFT detectAndCompute"
    figures = {
        floor: cpu_and_wall(lambda: detector.detectAndCompute(view.image, mask), repeats),
        f"describe, raw 752 x 564 ({len(method.describe(view))} keypoints; target < 150)": (
            cpu_and_wall(lambda: method.describe(view), repeats)
        ),
    }
    print_figures(figures, floor)


def bench_home(current: SiftFeatures, goal: SiftFeatures, repeats: int) -> None:
    """``home`` and the descriptor matching against ``cv2.BFMatcher.knnMatch`` (k = 2)."""
    p = Sift()
    pn = Sift(horizon_constraint=False, half_plane_constraint=False)
    matcher = cv2.BFMatcher(cv2.NORM_L2)

    def opencv() -> list[tuple[int, int]]:
        pairs = matcher.knnMatch(goal.descriptors, current.descriptors, k=2)
        return [(m.queryIdx, m.trainIdx) for m, n in pairs if m.distance < p.ratio * n.distance]

    floor = f"floor: cv2.BFMatcher.knnMatch, k = 2 ({len(goal)} x {len(current)})"
    figures = {
        floor: cpu_and_wall(
            lambda: matcher.knnMatch(goal.descriptors, current.descriptors, k=2), repeats
        ),
        "matching (numpy, with the ratio test)": cpu_and_wall(
            lambda: match_descriptors(goal.descriptors, current.descriptors, p.ratio, False),
            repeats,
        ),
    }
    for label, method in (("P", p), ("PN", pn)):
        estimate = method.home(current, goal)
        counts = f"{estimate.diagnostics['n_matches']} matches, {estimate.n_landmarks} landmarks"
        figures[f"home {label} ({counts}; target < 10)"] = cpu_and_wall(
            lambda m=method: m.home(current, goal), repeats
        )
    print_figures(figures, floor)
    ig, ic = match_descriptors(goal.descriptors, current.descriptors, p.ratio, False)
    same = set(zip(ig.tolist(), ic.tolist(), strict=True)) == set(opencv())
    print(f"  same matches as cv2.BFMatcher with the ratio test: {same}")


def main() -> None:
    as_in_job_workers()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print(load())
    current_view, goal_view = _views()
    p = Sift()
    bench_describe(current_view, p, max(1, args.repeats // 4))
    current, goal = p.describe(current_view), p.describe(goal_view)
    bench_home(current, goal, args.repeats)
    ig, ic = match_descriptors(goal.descriptors, current.descriptors, p.ratio, False)
    bench_solver(goal.azimuths[ig], current.azimuths[ic], p.max_triples, args.repeats)
    print(load())


if __name__ == "__main__":
    main()
