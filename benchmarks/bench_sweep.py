"""Throughput of whole runs: jobs and pairs per second per method, --jobs 1 against --jobs 2.

    python benchmarks/bench_sweep.py                 # 6 goals of synth-original, each method
    python benchmarks/bench_sweep.py --full          # also all 28,730 pairs of the 10 x 17 grid

Each measurement is a fresh run folder (features and jobs computed from scratch; the generated
database is generated once beforehand and not timed). The ratio column compares --jobs 2 with
the --jobs 1 reference measured in the same process.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from homebench.config import RunConfig
from homebench.data.catalog import ensure_generated
from homebench.evaluation.runner import Execution, run_plan

METHODS = ("warping", "sift", "klt-sector")


def _config(output: Path, method: str, goals: object) -> RunConfig:
    return RunConfig.model_validate(
        {
            "output": str(output),
            "databases": {"original": "synth-original"},
            "conditions": ["original-original"],
            "goals": goals,
            "methods": [{"method": method}],
        }
    )


def _timed_run(method: str, goals: object, jobs: int) -> tuple[float, int, int]:
    """Seconds, home jobs and pairs of one fresh run."""
    with tempfile.TemporaryDirectory() as folder:
        config = _config(Path(folder) / "run", method, goals)
        start = time.perf_counter()
        outcome = run_plan(config, Path("bench"), Execution(jobs=jobs), show_progress=False)
        seconds = time.perf_counter() - start
        if outcome.failures:
            raise SystemExit(f"{method}: {len(outcome.failures)} job(s) failed")
        pairs = sum(len(job.currents) for job in outcome.plan.home)
        return seconds, len(outcome.plan.home), pairs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="also time all-pairs runs (--jobs 2)")
    parser.add_argument("--goals", type=int, default=6, help="goals of the throughput runs")
    args = parser.parse_args()
    ensure_generated("synth-original", jobs=2)
    goals = {"random": args.goals, "seed": 1}
    print(f"{'method':<12} {'jobs':>4} {'seconds':>8} {'jobs/s':>7} {'pairs/s':>8} {'ratio':>6}")
    for method in METHODS:
        reference = None
        for n in (1, 2):
            seconds, n_jobs, pairs = _timed_run(method, goals, n)
            reference = reference or seconds
            print(
                f"{method:<12} {n:>4} {seconds:>8.2f} {n_jobs / seconds:>7.2f} "
                f"{pairs / seconds:>8.0f} {reference / seconds:>6.2f}"
            )
    if args.full:
        total = 0.0
        for method in METHODS:
            load = os.getloadavg()[0]
            seconds, _, pairs = _timed_run(method, "all", 2)
            total += seconds
            print(
                f"all pairs, {method:<12}: {pairs} pairs in {seconds:.0f} s (--jobs 2), "
                f"load before/after {load:.2f}/{os.getloadavg()[0]:.2f}"
            )
        print(f"all three methods, full grid of one condition: {total:.0f} s (target < 180 s)")


if __name__ == "__main__":
    main()
