"""Min-warping per pair against a floor and, side by side, Möller's C++ code (one thread).

For goal (5, 9) of a generated 10 x 17 grid of 288 x 72 panoramas against every other position
(see ``benchmarks/peer.py``), in alternated rounds (medians reported, with the load at the
start of each round; ratios CPU over CPU): the process CPU and wall time per pair of ``home``
(``describe`` excluded: homebench describes each view once, while the peer's time per pair, as
``peer.py``'s driver measures it, includes its first phase, the edge filter and the scale-plane
stack, on both images of every pair; so these ratios favour homebench by that phase), with
double and fine search (the default) and with both off,

- in this plain Python process (as the API, a notebook or a benchmark calls it) and in an
  isolated job worker (forked from a worker server, the workers' allocator settings);
- the floor, measured in this process: one ``np.minimum.reduce`` over an 8-bit stack of the
  search's size (9 x 288 x 288);
- with ``--peer PATH``: the peer with the same searches on homebench's band and on the full
  image;

and the AE of each. Then the kernels' import (compiled, or loaded from numba's cache), where
a pair's CPU goes (stack, tables, coarse searches, fine search) and ``describe`` per view, in
this process.

Run: ``python benchmarks/bench_min_warping.py [--rounds N] [--pairs N] [--peer PATH]
[--cold]``; ``--cold`` compiles the kernels into an empty numba cache (a fresh install's first
import).
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
import functools  # noqa: E402
import importlib  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import peer  # noqa: E402
from timing import cpu_and_wall, load  # noqa: E402

from homebench.methods.base import View  # noqa: E402
from homebench.methods.min_warping.method import MinWarping  # noqa: E402

SETTINGS = {"double + fine": {}, "searches off": {"double_search": False, "fine_search": False}}


def import_kernels() -> None:
    """Import the kernels (they compile, or load from the cache, as they are imported)."""
    start = time.process_time()
    kernels = importlib.import_module("homebench.methods.min_warping.kernels")
    cpu = time.process_time() - start
    misses = sum(len(getattr(kernels, name).stats.cache_misses) for name in kernels.SIGNATURES)
    how = f"compiled ({misses} kernels)" if misses else "loaded from numba's cache"
    print(f"kernels imported: {how}, {cpu:.2f} s CPU")


def floor_figure(repeats: int) -> peer.Figure:
    """The floor: CPU and wall ms of one np.minimum.reduce over a 9 x 288 x 288 uint8 stack."""
    stack = np.zeros((9, 288, 288), dtype=np.uint8)
    start = peer.load()
    cpu, wall = cpu_and_wall(lambda: np.minimum.reduce(stack, axis=0), repeats)
    return peer.Figure(1e3 * cpu, 1e3 * wall, (), start)


def parts(current: np.ndarray, goal: np.ndarray, view: View) -> None:
    """Where a pair's CPU goes, and ``describe`` of ``view`` (once per view: the peer repeats
    its part of it, edge filter and magnification, for every pair), in this process (best of
    three rounds of 20 calls)."""
    method = MinWarping()
    stack = method.quantized_stack(current, goal, "numba")
    searcher = method.searcher(stack, "numba")
    alphas = np.arange(25)
    calls = {
        "home, double + fine": lambda: method.home(current, goal),
        "stack: distances and 8 bits": lambda: method.quantized_stack(current, goal, "numba"),
        "two tables and coarse searches": lambda: [
            method.searcher(stack, "numba").coarse(swap) for swap in (False, True)
        ],
        "fine search, 2 x 25 pairs": lambda: [searcher.at(alphas, alphas, s) for s in (0, 1)],
        "describe, once per view": lambda: method.describe(view),
    }
    print("where a pair's CPU goes (this process):")
    for label, call in calls.items():
        cpu, wall = cpu_and_wall(call, 20)
        print(f"  {label:32s} CPU {1e3 * cpu:6.2f} ms, wall {1e3 * wall:6.2f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5, help="alternated rounds")
    parser.add_argument("--pairs", type=int, default=None, help="the first N pairs only")
    parser.add_argument("--peer", type=Path, help="the peer's driver (see benchmarks/peer.py)")
    parser.add_argument("--cold", action="store_true", help="compile into an empty numba cache")
    args = parser.parse_args()
    print(load())
    import_kernels()
    positions = peer.currents(args.pairs)
    described = {ij: MinWarping().describe(peer.views()[ij]) for ij in [peer.GOAL, *positions]}
    goal, currents = described[peer.GOAL], [described[ij] for ij in positions]
    worker = peer.JobWorker(MinWarping.preload_modules)
    driver = peer.Peer(args.peer, positions) if args.peer else None
    print(f"goal {peer.GOAL} against {len(positions)} positions, 288 x 72, seed 0; {args.rounds} "
          "alternated rounds; ratios: CPU over the median CPU of the column's figure")  # fmt: skip
    try:
        for setting, params in SETTINGS.items():
            method, make = MinWarping(**params), functools.partial(MinWarping, **params)
            figures = {
                "floor": lambda: floor_figure(100),
                "homebench, this process": peer.homebench_figure(
                    lambda m=method: peer.method_pass(m, currents, goal)
                ),
                "homebench, job worker": peer.homebench_figure(
                    lambda make=make: worker.method_pass(make, currents, goal)
                ),
            }
            if driver is not None:
                for kind in ("band", "full"):
                    figures[f"peer, {kind}"] = functools.partial(
                        driver.run, "min", bool(params == {}), kind
                    )
            print(f"{setting}:")
            results = peer.alternate(args.rounds, figures)
            bases = {"/ floor": "floor", "/ peer band": "peer, band", "/ peer full": "peer, full"}
            peer.report(results, positions, bases)
    finally:
        worker.close()
    parts(currents[0], goal, peer.views()[peer.GOAL])
    print(load())


if __name__ == "__main__":
    main()
