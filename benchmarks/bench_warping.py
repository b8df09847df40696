"""Warping (Table 1 grid, 20 x 72 x 72) per pair against its floor, one thread.

One goal against every other position of a generated 10 x 17 grid (288 x 72 unfolded
panoramas, seed 0), as a job runs them. Prints per-call process CPU time (``time.process_time``)
and wall time of:

- the floor, measured in the same process: a float32 matrix product of the search's size,
  (n_rho * n_alpha, n) x (n, n_psi) = (1440 x 72) x (72 x 72);
- ``home`` per pair with the goal's part of the screen kept (every pair of a job after its
  first), and with it rebuilt every call (the cost of a job's first pair);
- ``describe`` per view;

each with its ratio to the floor (target: home within 2x), and the load average before and after.
Checks that ``home`` gives the first minimum of :meth:`Warping.costs` (the exact float64 search)
on every pair, and that the costs are those of the direct search (tests/warping_reference.py,
``np.interp`` per hypothesis) on one pair.

Run: ``python benchmarks/bench_warping.py [--repeats N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import itertools  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the direct search
from timing import as_in_job_workers, cpu_and_wall, load, print_figures  # noqa: E402
from warping_reference import direct_costs  # noqa: E402

from homebench.data.synth.spec import WorldSpec  # noqa: E402
from homebench.data.synth.world import render_position  # noqa: E402
from homebench.methods.base import View  # noqa: E402
from homebench.methods.warping.method import Warping, best_hypothesis  # noqa: E402

SPEC = WorldSpec(
    seed=0,
    grid={"shape": [10, 17]},
    unfolded={"width": 288, "elevation_top_deg": 45.0, "elevation_bottom_deg": -45.0},
)
GOAL = (5, 8)


def main() -> None:
    as_in_job_workers()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="rounds over all pairs")
    repeats = parser.parse_args().repeats
    print(load())
    method = Warping()
    geometry = SPEC.unfolded.geometry()
    views = {
        (i, j): View(render_position(SPEC, i, j)["unfolded"], geometry)
        for i, j in SPEC.to_grid().indices()
    }
    signals = {ij: method.describe(view) for ij, view in views.items()}
    goal = signals[GOAL]
    currents = [signal for ij, signal in signals.items() if ij != GOAL]
    pairs = itertools.cycle(currents)

    shape = (method.n_rho * method.n_alpha, method.n_columns, method.n_psi)
    rng = np.random.default_rng(0)
    left = rng.random(shape[:2], dtype=np.float32)
    right = rng.random(shape[1:], dtype=np.float32)
    floor = cpu_and_wall(lambda: left @ right, 50 * repeats)
    n = len(currents) * repeats
    kept = cpu_and_wall(lambda: method.home(next(pairs), goal), n)
    fresh = cpu_and_wall(lambda: (method._screens.clear(), method.home(next(pairs), goal)), n)
    describe = cpu_and_wall(lambda: method.describe(views[GOAL]), 20 * repeats)

    print(f"warping {method.n_rho} x {method.n_alpha} x {method.n_psi}, one thread, goal {GOAL}")
    floor_label = f"floor: float32 ({shape[0]} x {shape[1]}) x ({shape[1]} x {shape[2]})"
    figures = {
        floor_label: floor,
        "home, goal kept (a job's pairs)": kept,
        "home, goal's part rebuilt every call": fresh,
        "describe (288 x 72 -> 72)": describe,
    }
    print_figures(figures, floor_label)

    same = all(
        method.home(current, goal) == best_hypothesis(method.costs(current, goal), method.rho, 72)
        for current in currents
    )
    print(f"  home = first minimum of the exact costs on all {len(currents)} pairs: {same}")
    costs = method.costs(currents[0], goal)
    direct = direct_costs(method, currents[0], goal)
    close = np.allclose(costs, direct, rtol=1e-12) and np.argmin(costs) == np.argmin(direct)
    print(f"  exact costs = direct search (np.interp per hypothesis) on one pair: {close}")
    print(load())


if __name__ == "__main__":
    main()
