"""Throughput of whole runs: jobs and pairs per second per method, --jobs 1 against --jobs 2.

    python benchmarks/bench_sweep.py                 # 6 goals of synth-original, each method
    python benchmarks/bench_sweep.py --full          # also all 28,730 pairs of the 10 x 17 grid

Each measurement is a fresh run folder (features and jobs computed from scratch; the generated
database is generated once beforehand and not timed): its wall time, its CPU time (this
process and its workers), and that CPU over the floor: the bare method's CPU over the run's
plan (every image it needs described once, every pair homed), measured after the run in an
isolated job worker as the jobs run (``bench_run.py``'s floor). Both are process CPU time: the
times in the result rows are wall times (a busy machine inflates them) and a worker's first
call of a method has none. The speed-up column compares --jobs 2 with the --jobs 1 reference
measured in the same process (wall over wall); the load average is printed before and after
each line.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from bench_run import DATABASE, floor_in_worker, run_config, timed_run

from homebench.data.catalog import ensure_generated

METHODS = ("warping", "sift", "klt-sector")


def _timed_run(method: str, goals: object, jobs: int) -> tuple[float, float, float, int, int]:
    """Wall and CPU seconds of one fresh run, the floor's CPU seconds over its plan, its home
    jobs and pairs."""
    with tempfile.TemporaryDirectory() as folder:
        config = run_config(Path(folder) / "run", method, goals)
        outcome, seconds, cpu = timed_run(config, jobs)
        floor, pairs = floor_in_worker(outcome.plan.home)
        return seconds, cpu, floor, len(outcome.plan.home), pairs


def _line(method: str, jobs: int, run: tuple[float, float, float, int, int], load: float) -> str:
    seconds, cpu, floor, n_jobs, pairs = run
    return (
        f"{method:<12} {jobs:>4} {pairs:>6} {seconds:>8.2f} {cpu:>7.2f} {floor:>9.2f} "
        f"{cpu / floor:>7.2f} {n_jobs / seconds:>7.2f} {pairs / seconds:>8.0f}"
        f"  {load:.2f}/{os.getloadavg()[0]:.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="also time all-pairs runs (--jobs 2)")
    parser.add_argument("--goals", type=int, default=6, help="goals of the throughput runs")
    args = parser.parse_args()
    ensure_generated(DATABASE, jobs=2)
    goals = {"random": args.goals, "seed": 1}
    print(
        f"{'method':<12} {'jobs':>4} {'pairs':>6} {'wall s':>8} {'CPU s':>7} {'floor CPU':>9} "
        f"{'/ floor':>7} {'jobs/s':>7} {'pairs/s':>8}  load before/after, speed-up"
    )
    for method in METHODS:
        walls = {}
        for n in (1, 2):
            load = os.getloadavg()[0]
            run = _timed_run(method, goals, n)
            walls[n] = run[0]
            print(_line(method, n, run, load) + f"  {walls[1] / walls[n]:.2f}x")
    if args.full:
        total = 0.0
        for method in METHODS:
            load = os.getloadavg()[0]
            run = _timed_run(method, "all", 2)
            total += run[0]
            print(_line(method, 2, run, load) + "  (all pairs)")
        print(f"all three methods, full grid of one condition: {total:.0f} s (target < 180 s)")


if __name__ == "__main__":
    main()
