"""The overhead of whole runs: CPU per pair of a run against the bare method, --jobs 1 and 2.

    python benchmarks/bench_run.py                        # 4 goals of synth-original
    python benchmarks/bench_run.py --goals 10 --methods warping sift
    python benchmarks/bench_run.py --goals all --methods warping   # all 28,730 pairs
    python benchmarks/bench_run.py --goals 40 --repeats 3          # alternated, medians

For each method: the floor, the method alone (``describe`` of every image the run needs once,
then ``home`` of every pair with what it needs beyond the two views; images decoded and one
warm-up call made beforehand, not timed), as process CPU per pair, in an isolated worker as
the jobs run (one thread per numeric library, their allocator settings, forked from a worker
server); for a method with a batch call, also the batch floor: each job's pairs homed by one
``home_many`` call, as the runs call it (:func:`homebench.methods.base.home_many`; the same
as the floor for other methods). Then fresh runs of the same plan (``run_plan`` in a new
folder, workers included: the CPU of this process and its waited-for children per pair) with
--jobs 1 and --jobs 2. Ratios, CPU over CPU: the run's CPU per pair over the floor's and over
the batch floor's (target 1.15); and the throughput of --jobs 2 over --jobs 1's, which is
--jobs 1 wall time over --jobs 2's (target 1.8 on an idle 2-core machine). A run also pays costs
that do not grow with its pairs (the worker server's imports, planning, the run's records,
opening the databases in each worker): "fixed CPU" (s) is the CPU of a one-goal run of the
method beyond its own batch floor (the median of three), and "marginal" the run's CPU without it
over the batch floor's, at --jobs 1 / --jobs 2. The load average before and after each line says
how busy the machine was. With ``--repeats N`` the floors and the runs alternate N times
(floor, batch floor, --jobs 1, --jobs 2, then again) and each figure is the median of its N
measurements; the ratios' lowest and highest over the repeats follow in brackets.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import cv2
from timing import cpu_with_children, machine_cpu_s, others_cores, speedup

from homebench.config import RunConfig
from homebench.data.catalog import ensure_generated
from homebench.evaluation.executors import PRELOAD
from homebench.evaluation.isolation import Crash, WorkerPool
from homebench.evaluation.jobs import _GridViews
from homebench.evaluation.plan import HomeJob, ImageTask, make_plan
from homebench.evaluation.runner import Execution, RunOutcome, run_plan
from homebench.evaluation.sources import load_view, open_source, prepare_sources
from homebench.methods.base import batch_home, home_many

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


def _random_goals(goals: int | str) -> dict[str, int] | str:
    """A config's goals: ``goals`` at random (seed 1), or ``"all"``."""
    return goals if goals == "all" else {"random": int(goals), "seed": 1}


def _floor(jobs: tuple[HomeJob, ...], batch: bool = False) -> tuple[float, int]:
    """Process CPU seconds of the bare method over the plan's pairs, and the pair count; with
    ``batch``, each job's pairs homed by one :func:`~homebench.methods.base.home_many` call."""
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
        extras = [
            views.extra(task, database.heading(task.i, task.j) + task.rotation)
            for task in job.currents
        ]
        goal = features[job.goal]
        if batch:
            names = extras[0].keys() if extras else ()
            currents = [features[task] for task in job.currents]
            home_many(method, currents, goal, **{k: [e[k] for e in extras] for k in names})
        else:
            for task, extra in zip(job.currents, extras, strict=True):
                method.home(features[task], goal, **extra)
        pairs += len(job.currents)
    return time.process_time() - start, pairs


def _batch_floor(jobs: tuple[HomeJob, ...]) -> tuple[float, int]:
    """:func:`_floor` with each job's pairs in one batch call."""
    return _floor(jobs, batch=True)


def floor_in_worker(jobs: tuple[HomeJob, ...], batch: bool = False) -> tuple[float, int]:
    """:func:`_floor` (with ``batch``, :func:`_batch_floor`) in an isolated worker, as the
    jobs run."""
    import bench_run  # workers import a function by its module's name, not from "__main__"

    with WorkerPool(1, preload=PRELOAD) as pool:
        work = bench_run._batch_floor if batch else bench_run._floor
        ((_, result),) = pool.map_unordered(work, [jobs])
    if isinstance(result, Crash):
        raise SystemExit(f"the floor's worker failed: {result.cause}")
    return result


def timed_run(config: RunConfig, jobs: int) -> tuple[RunOutcome, float, float, float]:
    """One fresh run: its outcome, its wall and CPU seconds (this process and its workers)
    and the cores other processes kept busy meanwhile; SystemExit if a job failed."""
    machine, wall, cpu = machine_cpu_s(), time.perf_counter(), cpu_with_children()
    outcome = run_plan(config, Path("bench"), Execution(jobs=jobs), show_progress=False)
    wall, cpu = time.perf_counter() - wall, cpu_with_children() - cpu
    if outcome.failures:
        raise SystemExit(f"{len(outcome.failures)} job(s) failed: {outcome.failures[0].error}")
    return outcome, wall, cpu, others_cores(wall, cpu, machine)


def _measure(
    folder: Path, method: str, goals: int | str
) -> tuple[tuple[float, float], int, dict[int, tuple]]:
    """The floor's and the batch floor's CPU seconds and the pair count of a plan of ``goals``
    goals, and the wall and CPU seconds of fresh runs of it with --jobs 1 and 2."""
    config = run_config(folder / "plan", method, _random_goals(goals))
    plan = make_plan(config, prepare_sources(config, 2), Path("bench"))
    floor, pairs = floor_in_worker(plan.home)
    batched = batch_home(plan.home[0].method.create()) is not None
    batch_floor = floor_in_worker(plan.home, batch=True)[0] if batched else floor
    runs = {
        n: timed_run(run_config(folder / f"jobs{n}", method, _random_goals(goals)), n)[1:]
        for n in (1, 2)
    }
    return (floor, batch_floor), pairs, runs


def _medians(measured: list[tuple]) -> tuple:
    """The median of each figure of :func:`_measure`'s results over repeats (pairs: the same)."""
    floors = tuple(statistics.median(m[0][k] for m in measured) for k in (0, 1))
    runs = {
        n: tuple(statistics.median(m[2][n][k] for m in measured) for k in (0, 1, 2)) for n in (1, 2)
    }
    return floors, measured[0][1], runs


def _spread(measured: list[tuple]) -> str:
    """The lowest and highest j1 / j2 ratio over the batch floor and speed-up over repeats."""
    if len(measured) < 2:
        return ""
    ratios = {n: [m[2][n][1] / m[0][1] for m in measured] for n in (1, 2)}
    return (
        "  ["
        + "; ".join(
            f"{label} {min(v):.2f}-{max(v):.2f}"
            for label, v in (("j1", ratios[1]), ("j2", ratios[2]))
        )
        + "]"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", default="4", help="goals (all currents each), or 'all'")
    parser.add_argument("--methods", nargs="+", default=list(METHODS))
    parser.add_argument("--repeats", type=int, default=1, help="alternated measurements")
    args = parser.parse_args()
    ensure_generated(DATABASE, jobs=2)
    print("per pair: process CPU ms (this process and its workers for the runs); whole runs: s;")
    print(
        "ratio: a run's CPU over the floor's / over the batch floor's; speed-up: j1 over j2 wall, "
        "only where other work left the run 2 cores (timing.speedup)"
    )
    print(
        f"{'method':<12} {'pairs':>5} {'floor CPU':>9} {'batch':>6} {'j1 CPU':>7} {'ratio':>9} "
        f"{'j2 CPU':>7} {'ratio':>9} {'j1 wall':>7} {'j2 wall':>7} "
        f"{'fixed CPU':>9} {'marginal':>9}  load before/after; speed-up"
    )
    for name in args.methods:
        load = os.getloadavg()[0]
        with tempfile.TemporaryDirectory() as folder:
            measured = [
                _measure(Path(folder) / f"all{k}", name, args.goals) for k in range(args.repeats)
            ]
            ones = [_measure(Path(folder) / f"one{k}", name, 1) for k in range(FIXED_REPEATS)]
        floors, pairs, runs = _medians(measured)
        floor_ms, batch_ms = (1000.0 * floor / pairs for floor in floors)
        per_pair = {n: 1000.0 * run[1] / pairs for n, run in runs.items()}
        ratios = {n: f"{per_pair[n] / floor_ms:.2f}/{per_pair[n] / batch_ms:.2f}" for n in runs}
        # beyond the batch floor, as the runs call the method
        fixed = {n: statistics.median(run[n][1] - one_floors[1] for one_floors, _, run in ones)
                 for n in runs}  # fmt: skip
        marginal = {n: (runs[n][1] - fixed[n]) / floors[1] for n in runs}
        print(
            f"{name:<12} {pairs:>5} {floor_ms:>9.2f} {batch_ms:>6.2f} {per_pair[1]:>7.2f} "
            f"{ratios[1]:>9} {per_pair[2]:>7.2f} {ratios[2]:>9} "
            f"{runs[1][0]:>7.2f} {runs[2][0]:>7.2f} "
            f"{fixed[1]:>4.2f}/{fixed[2]:>4.2f} {marginal[1]:>4.2f}/{marginal[2]:>4.2f}  "
            f"{load:.2f}/{os.getloadavg()[0]:.2f}; {speedup(runs[1][0], runs[2][0], 2, runs[2][2])}"
            f"{_spread(measured)}",
            flush=True,
        )


if __name__ == "__main__":
    main()
