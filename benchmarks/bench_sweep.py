"""Throughput of whole runs: jobs and pairs per second per method, --jobs 1 against --jobs 2.

    python benchmarks/bench_sweep.py                 # 6 goals of synth-original, each method
    python benchmarks/bench_sweep.py --full          # also all 28,730 pairs of the 10 x 17 grid

Each measurement is a fresh run folder (features and jobs computed from scratch; the generated
database is generated once beforehand and not timed): its wall time, its CPU time (this
process and its workers), and that CPU over a floor measured in the same run, the method's
own time (every pair's ``home`` and every image's ``describe`` once, as the jobs record them in
the result rows). The speed-up column compares --jobs 2 with the --jobs 1 reference measured
in the same process; the load average is printed before and after each line.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
from pathlib import Path

from bench_run import DATABASE, run_config, timed_run

from homebench.data.catalog import ensure_generated
from homebench.evaluation.plan import Plan

METHODS = ("warping", "sift", "klt-sector")


def _method_seconds(plan: Plan, run_dir: Path) -> float:
    """Seconds the method itself took in a run: every pair's ``home`` and every current
    view's ``describe`` once, as the result rows record them."""
    home, describe = 0.0, {}
    for job in plan.home:
        for row in json.loads(job.result_path(run_dir).read_bytes())["rows"]:
            home += row["home_ms"] or 0.0
            describe[row["current_i"], row["current_j"], row["rotation"]] = row["describe_ms"]
    return (home + sum(ms or 0.0 for ms in describe.values())) / 1000.0


def _timed_run(method: str, goals: object, jobs: int) -> tuple[float, float, float, int, int]:
    """Wall and CPU seconds, the method's own seconds, home jobs and pairs of one fresh run."""
    with tempfile.TemporaryDirectory() as folder:
        config = run_config(Path(folder) / "run", method, goals)
        outcome, seconds, cpu = timed_run(config, jobs)
        pairs = sum(len(job.currents) for job in outcome.plan.home)
        own = _method_seconds(outcome.plan, config.output)
        return seconds, cpu, own, len(outcome.plan.home), pairs


def _line(method: str, jobs: int, run: tuple[float, float, float, int, int], load: float) -> str:
    seconds, cpu, own, n_jobs, pairs = run
    return (
        f"{method:<12} {jobs:>4} {pairs:>6} {seconds:>8.2f} {cpu:>7.2f} {cpu / own:>7.2f} "
        f"{n_jobs / seconds:>7.2f} {pairs / seconds:>8.0f}"
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
        f"{'method':<12} {'jobs':>4} {'pairs':>6} {'wall s':>8} {'CPU s':>7} {'/ floor':>7} "
        f"{'jobs/s':>7} {'pairs/s':>8}  load before/after, speed-up"
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
