"""Min-warping per pair (one thread): CPU and wall time, compile time, a floor, and AE.

Prints, for one rendered pair of a generated world (288 x 72 unfolded panoramas, seed 0):

- the numba compile (or cache load) time of the kernels, first calls in this process;
- per-pair process CPU time (``time.process_time``) and wall time of ``home`` (describe
  excluded, as in Möller's figures) for the pure-numpy reference, the compiled path without
  double / fine search, and with them (Möller's SIMD C++ on this machine type, issue 16: 16.0 ms
  without, 29.7 ms with; targets 5 ms and 10 ms);
- a floor measured in the same process: one ``np.minimum.reduce`` pass over a uint16 array of
  the stack's size (9 x 288 x 288) and its ratio to each figure, plus the load average;
- AE (deg) to the true home direction of one goal against every other position of a 10 x 17
  grid, for the former setting (96-column band, no double / fine search) and the four
  combinations of double / fine search on the 288-column band (C++ code: about 0.9 deg).

Run: ``python benchmarks/bench_min_warping.py [--repeats N] [--cold] [--no-ae]``; ``--cold``
compiles into an empty numba cache (the first-call compile time of a fresh install).
"""

from __future__ import annotations

import os
import sys
import tempfile

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
if "--cold" in sys.argv:
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="numba-cold-")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from timing import as_in_job_workers, cpu_and_wall  # noqa: E402

from homebench.data.synth.spec import WorldSpec  # noqa: E402
from homebench.data.synth.world import render_position  # noqa: E402
from homebench.geometry import angular_error, home_direction  # noqa: E402
from homebench.methods import min_warping_kernels as kernels  # noqa: E402
from homebench.methods.base import View  # noqa: E402
from homebench.methods.min_warping import MinWarping  # noqa: E402

SPEC = WorldSpec(
    seed=0,
    grid={"shape": [10, 17]},
    unfolded={"width": 288, "elevation_top_deg": 45.0, "elevation_bottom_deg": -45.0},
)
GOAL = (5, 8)
CONFIGS = {
    "before (96 cols, single)": MinWarping(
        columns_per_step=1, double_search=False, fine_search=False
    ),
    "288 cols, single": MinWarping(double_search=False, fine_search=False),
    "288 cols, double": MinWarping(fine_search=False),
    "288 cols, fine": MinWarping(double_search=False),
    "288 cols, double + fine": MinWarping(),
}


def _view(i: int, j: int) -> View:
    return View(render_position(SPEC, i, j)["unfolded"], SPEC.unfolded.geometry())


def _compilecpu_and_wall(current: np.ndarray, goal: np.ndarray) -> None:
    method = MinWarping()
    start = time.perf_counter()
    method.home(current, goal)
    first = time.perf_counter() - start
    hits = sum(len(f.stats.cache_hits) for f in _dispatchers())
    misses = sum(len(f.stats.cache_misses) for f in _dispatchers())
    source = "compiled" if misses else "loaded from the cache"
    print(f"numba first call (kernels {source}: {hits} hits, {misses} misses): {first:.2f} s")


def _dispatchers() -> list:
    names = ("distance_planes", "quantize", "search_table", "coarse_costs", "table_costs")
    return [getattr(kernels, name) for name in names]


def timing(current: np.ndarray, goal: np.ndarray, repeats: int) -> None:
    stack = np.zeros((9, 288, 288), dtype=np.uint16)
    floor = cpu_and_wall(lambda: np.minimum.reduce(stack, axis=0), repeats * 10)[0]
    rows = [
        ("numpy reference, double + fine", MinWarping(), "numpy", 1),
        ("compiled, single", CONFIGS["288 cols, single"], "numba", repeats),
        ("compiled, double", CONFIGS["288 cols, double"], "numba", repeats),
        ("compiled, double + fine", MinWarping(), "numba", repeats),
    ]
    print(f"floor: np.minimum.reduce over a 9 x 288 x 288 uint16 stack {floor * 1e3:.3f} ms")
    print(f"{'home() per pair':34s} {'CPU ms':>8s} {'wall ms':>8s} {'/ floor':>8s}")
    for label, method, engine, n in rows:
        cpu, wall = cpu_and_wall(lambda m=method, e=engine: m.home(current, goal, engine=e), n)
        print(f"{label:34s} {cpu * 1e3:8.2f} {wall * 1e3:8.2f} {cpu / floor:8.0f}")
    method = MinWarping()
    stack16 = method.quantized_stack(current, goal, "numba")
    parts = {
        "stack (distances + 16-bit)": lambda: method.quantized_stack(current, goal, "numba"),
        "one coarse search": lambda: method.coarse(stack16, "numba"),
        "search, double + fine": lambda: method.search(stack16),
    }
    for label, function in parts.items():
        cpu, wall = cpu_and_wall(function, repeats)
        print(f"  {label:32s} {cpu * 1e3:8.2f} {wall * 1e3:8.2f} {cpu / floor:8.0f}")


def accuracy() -> None:
    goal_pose = SPEC.pose(*GOAL)
    others = [(i, j) for i, j in SPEC.to_grid().indices() if (i, j) != GOAL]
    views = {ij: _view(*ij) for ij in [GOAL, *others]}
    print(f"AE over {len(others)} pairs, goal {GOAL} of a 10 x 17 grid (288 x 72, seed 0):")
    print(f"{'setting':28s} {'mean':>6s} {'median':>6s} {'none':>5s} {'CPU ms/pair':>11s}")
    for label, method in CONFIGS.items():
        goal = method.describe(views[GOAL])
        errors, missing, cpu = [], 0, 0.0
        for ij in others:
            current = method.describe(views[ij])
            start = time.process_time()
            estimate = method.home(current, goal)
            cpu += time.process_time() - start
            pose = SPEC.pose(*ij)
            truth = home_direction((pose.x, pose.y), (goal_pose.x, goal_pose.y), pose.heading)
            if estimate.angle is None:
                missing += 1
            else:
                errors.append(math.degrees(angular_error(estimate.angle, truth)))
        print(
            f"{label:28s} {np.mean(errors):6.2f} {np.median(errors):6.2f} {missing:5d} "
            f"{cpu / len(others) * 1e3:11.2f}"
        )


def main() -> None:
    as_in_job_workers()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--cold", action="store_true", help="compile into an empty numba cache")
    parser.add_argument("--no-ae", action="store_true", help="timing only")
    args = parser.parse_args()
    print(f"load average at start: {os.getloadavg()}")
    method = MinWarping()
    current_view, goal_view = _view(3, 12), _view(*GOAL)
    current, goal = method.describe(current_view), method.describe(goal_view)
    _compilecpu_and_wall(current, goal)
    timing(current, goal, args.repeats)
    if not args.no_ae:
        accuracy()
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
