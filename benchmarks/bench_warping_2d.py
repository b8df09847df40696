"""Warping-2d per pair against a floor and, side by side, Möller's C++ 2D-warping (one thread).

For goal (5, 9) of a generated 10 x 17 grid of 288 x 72 panoramas against every other position
(see ``benchmarks/peer.py``), in alternated rounds (medians reported, with the load at the
start of each round; ratios CPU over CPU): the process CPU and wall time per pair of ``home``
(``describe`` excluded: homebench describes each view once, while the peer's time per pair, as
``peer.py``'s driver measures it, includes its first phase, the edge filter and the scale-plane
stack, on both images of every pair; so these ratios favour homebench by that phase),

- a job's pairs: a fresh method, so the goal's part (its warps and their spectra, computed
  once per goal) is paid once over the pairs; in this plain Python process and in an isolated
  job worker;
- the pairs after a job's first (the goal's part kept), in this process;
- the scale-plane scheme (``scheme="scale-planes"``, the way the peer runs 2D-warping), in
  this process and in a job worker;
- the floor, measured in this process: one ``np.add.reduce`` over the rows of the goal's
  spectra (1,920 x 16 x 49 complex), which every pair reads;
- with ``--peer PATH``: the peer's 2D-warping with double and fine search and without, on
  homebench's band and on the full image;

and the AE of each; with ``--peer``, a paired comparison of the scale-plane scheme's AE with
the peer's (double and fine search, band) over every pair of ``--ae-goals`` goals spread over the
grid (goal-bootstrap intervals, sign-flip test over goals); then the goal's part (CPU per goal)
and ``describe`` (per view).

Run: ``python benchmarks/bench_warping_2d.py [--rounds N] [--pairs N] [--peer PATH]
[--ae-goals N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import functools  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import peer  # noqa: E402
from timing import cpu_and_wall, load  # noqa: E402

from homebench.methods.warping_2d.method import Warping2D  # noqa: E402


def floor_figure(spectrum: np.ndarray, repeats: int) -> peer.Figure:
    """The floor: CPU and wall ms of one sum over the rows of the goal's spectra."""
    start = peer.load()
    cpu, wall = cpu_and_wall(lambda: np.add.reduce(spectrum, axis=1), repeats)
    return peer.Figure(1e3 * cpu, 1e3 * wall, (), start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5, help="alternated rounds")
    parser.add_argument("--pairs", type=int, default=None, help="the first N pairs only")
    parser.add_argument("--peer", type=Path, help="the peer's driver (see benchmarks/peer.py)")
    parser.add_argument(
        "--ae-goals", type=int, default=15, help="with --peer: goals of the paired AE comparison"
    )
    args = parser.parse_args()
    print(load())
    positions = peer.currents(args.pairs)
    views = peer.views()
    described = {ij: Warping2D().describe(views[ij]) for ij in [peer.GOAL, *positions]}
    goal, currents = described[peer.GOAL], [described[ij] for ij in positions]
    planes = functools.partial(Warping2D, scheme="scale-planes")
    plane_goal = planes().describe(views[peer.GOAL])
    plane_currents = [planes().describe(views[ij]) for ij in positions]
    kept = Warping2D()
    spectrum = kept.goal_part(goal, "numba").spectrum
    worker = peer.JobWorker(Warping2D.preload_modules)
    print(f"goal {peer.GOAL} against {len(positions)} positions, 288 x 72, seed 0; {args.rounds} "
          "alternated rounds; ratios: CPU over the median CPU of the column's figure")  # fmt: skip
    figures = {
        "floor": lambda: floor_figure(spectrum, 20),
        "homebench, a job, this process": peer.homebench_figure(
            lambda: peer.method_pass(Warping2D(), currents, goal, goal_kept=False)
        ),
        "homebench, a job, job worker": peer.homebench_figure(
            lambda: worker.method_pass(Warping2D, currents, goal, goal_kept=False)
        ),
        "homebench, goal's part kept": peer.homebench_figure(
            lambda: peer.method_pass(kept, currents, goal)
        ),
        "homebench scale-planes, this process": peer.homebench_figure(
            lambda: peer.method_pass(planes(), plane_currents, plane_goal)
        ),
        "homebench scale-planes, job worker": peer.homebench_figure(
            lambda: worker.method_pass(planes, plane_currents, plane_goal)
        ),
    }
    if args.peer:
        driver = peer.Peer(args.peer, positions)
        for searches, name in ((True, "double + fine"), (False, "searches off")):
            for kind in ("band", "full"):
                run = functools.partial(driver.run, "2d", searches, kind)
                figures[f"peer, {name}, {kind}"] = run
    try:
        results = peer.alternate(args.rounds, figures)
    finally:
        worker.close()
    bases = {
        "/ floor": "floor",
        "/ on band": "peer, double + fine, band",
        "/ on full": "peer, double + fine, full",
        "/ off band": "peer, searches off, band",
        "/ off full": "peer, searches off, full",
    }
    peer.report(results, positions, bases)
    if args.peer and args.ae_goals > 0:
        peer.compare_over_goals(peer.spread_goals(args.ae_goals), planes, driver, "2d")
    cpu, wall = cpu_and_wall(lambda: Warping2D().goal_part(goal, "numba"), 3)
    print(f"the goal's part, once per goal: CPU {1e3 * cpu:.1f} ms, wall {1e3 * wall:.1f} ms")
    cpu, wall = cpu_and_wall(lambda: kept.describe(views[peer.GOAL]), 20)
    print(f"describe, once per view: CPU {1e3 * cpu:.2f} ms, wall {1e3 * wall:.2f} ms")
    print(load())


if __name__ == "__main__":
    main()
