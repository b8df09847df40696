"""The overhead of whole runs: CPU per pair of a run against the bare method, --jobs 1 and 2.

    python benchmarks/bench_run.py                        # 4 goals of synth-original
    python benchmarks/bench_run.py --goals 10 --methods warping sift

For each method: the floor, the method alone (``describe`` of every image the run needs once,
then ``home`` of every pair with what it needs beyond the two views; images decoded and one
warm-up call made beforehand, not timed), as process CPU per pair, in an isolated worker as
the jobs run (one thread per numeric library, their allocator settings, forked from a worker
server); then fresh runs of the same plan (``run_plan`` in a new folder, workers included:
the CPU of this process and its waited-for children per pair) with --jobs 1 and --jobs 2.
Ratios: the run's CPU per pair over the floor's (target 1.15), and --jobs 1 wall time over
--jobs 2's (target 1.8 on an idle 2-core machine). A run also pays costs that do not grow with
its pairs (the worker server's imports, planning, the run's records, opening the databases in
each worker): "fixed CPU" (s) is the CPU of a one-goal run of the method beyond its own floor (the
median of three), and "marginal" the run's CPU per pair without it over the floor's, at
--jobs 1 / --jobs 2. The load average before and after each line says how busy the machine
was.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import cv2
from timing import cpu_with_children

from homebench.config import RunConfig
from homebench.data.catalog import ensure_generated
from homebench.evaluation.executors import PRELOAD
from homebench.evaluation.isolation import Crash, WorkerPool
from homebench.evaluation.jobs import _GridViews
from homebench.evaluation.plan import HomeJob, ImageTask, make_plan
from homebench.evaluation.runner import Execution, RunOutcome, run_plan
from homebench.evaluation.sources import load_view, open_source, prepare_sources

METHODS = ("warping", "min-warping", "sift", "klt-sector")
DATABASE = "synth-original"
#: One-goal runs whose median gives a run's fixed CPU (one run alone varies by about 0.3 s).
FIXED_REPEATS = 3


def run_config(output: Path, method: str, goals: object) -> RunConfig:
    """A run of ``method`` on the generated database, condition original-original; ``goals``
    as a config's (``{"random": n, "seed": 1}``, ``"all"``)."""
    return RunConfig.model_validate(
        {
            "output": str(output),
            "databases": {"original": DATABASE},
            "conditions": ["original-original"],
            "goals": goals,
            "methods": [{"method": method}],
        }
    )


def _random_goals(goals: int) -> dict[str, int]:
    return {"random": goals, "seed": 1}


def _floor(jobs: tuple[HomeJob, ...]) -> tuple[float, int]:
    """Process CPU seconds of the bare method over the plan's pairs, and the pair count."""
    cv2.setNumThreads(1)  # as in the workers: other threads' CPU would count in the floor
    method = jobs[0].method.create()
    images: dict[ImageTask, object] = {}
    for job in jobs:
        for task in (job.goal, *job.currents):
            images.setdefault(task, load_view(task.source, task.i, task.j, job.method.image_kind))
    first = next(iter(images.values()))
    method.home(method.describe(first), method.describe(first))  # warm-up (a JIT compiles)
    start = time.process_time()
    features = {task: method.describe(view) for task, view in images.items()}
    pairs = 0
    for job in jobs:
        views = _GridViews(job, method)
        database = open_source(job.currents[0].source)
        for task in job.currents:
            extra = views.extra(task, database.heading(task.i, task.j) + task.rotation)
            method.home(features[task], features[job.goal], **extra)
            pairs += 1
    return time.process_time() - start, pairs


def floor_in_worker(jobs: tuple[HomeJob, ...]) -> tuple[float, int]:
    """:func:`_floor` in an isolated worker, as the jobs run."""
    import bench_run  # workers import a function by its module's name, not from "__main__"

    with WorkerPool(1, preload=PRELOAD) as pool:
        ((_, result),) = pool.map_unordered(bench_run._floor, [jobs])
    if isinstance(result, Crash):
        raise SystemExit(f"the floor's worker failed: {result.cause}")
    return result


def timed_run(config: RunConfig, jobs: int) -> tuple[RunOutcome, float, float]:
    """One fresh run: its outcome, and its wall and CPU seconds (this process and its
    workers); SystemExit if a job failed."""
    wall, cpu = time.perf_counter(), cpu_with_children()
    outcome = run_plan(config, Path("bench"), Execution(jobs=jobs), show_progress=False)
    wall, cpu = time.perf_counter() - wall, cpu_with_children() - cpu
    if outcome.failures:
        raise SystemExit(f"{len(outcome.failures)} job(s) failed: {outcome.failures[0].error}")
    return outcome, wall, cpu


def _measure(folder: Path, method: str, goals: int) -> tuple[float, int, dict[int, tuple]]:
    """The floor's CPU seconds and pair count of a plan of ``goals`` goals, and the wall and
    CPU seconds of fresh runs of it with --jobs 1 and 2."""
    config = run_config(folder / "plan", method, _random_goals(goals))
    plan = make_plan(config, prepare_sources(config, 2), Path("bench"))
    floor, pairs = floor_in_worker(plan.home)
    runs = {
        n: timed_run(run_config(folder / f"jobs{n}", method, _random_goals(goals)), n)[1:]
        for n in (1, 2)
    }
    return floor, pairs, runs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", type=int, default=4, help="goals (all currents each)")
    parser.add_argument("--methods", nargs="+", default=list(METHODS))
    args = parser.parse_args()
    ensure_generated(DATABASE, jobs=2)
    print("per pair: process CPU ms (this process and its workers for the runs); whole runs: s")
    print(
        f"{'method':<12} {'pairs':>5} {'floor CPU':>9} {'j1 CPU':>7} {'ratio':>5} {'j2 CPU':>7} "
        f"{'ratio':>5} {'j1 wall':>7} {'j2 wall':>7} {'speed-up':>8} {'fixed CPU':>9} "
        f"{'marginal':>9}  load before/after"
    )
    for name in args.methods:
        load = os.getloadavg()[0]
        with tempfile.TemporaryDirectory() as folder:
            floor, pairs, runs = _measure(Path(folder) / "all", name, args.goals)
            ones = [_measure(Path(folder) / f"one{k}", name, 1) for k in range(FIXED_REPEATS)]
        per_pair = {n: 1000.0 * cpu / pairs for n, (_, cpu) in runs.items()}
        fixed = {n: statistics.median(run[n][1] - one_floor for one_floor, _, run in ones)
                 for n in runs}  # fmt: skip
        marginal = {n: (runs[n][1] - fixed[n]) / floor for n in runs}
        floor_ms = 1000.0 * floor / pairs
        print(
            f"{name:<12} {pairs:>5} {floor_ms:>9.2f} {per_pair[1]:>7.2f} "
            f"{per_pair[1] / floor_ms:>5.2f} {per_pair[2]:>7.2f} {per_pair[2] / floor_ms:>5.2f} "
            f"{runs[1][0]:>7.2f} {runs[2][0]:>7.2f} {runs[1][0] / runs[2][0]:>8.2f} "
            f"{fixed[1]:>4.2f}/{fixed[2]:>4.2f} {marginal[1]:>4.2f}/{marginal[2]:>4.2f}  "
            f"{load:.2f}/{os.getloadavg()[0]:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
