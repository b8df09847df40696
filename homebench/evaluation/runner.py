"""Running a plan: skip what is finished, run the rest in isolated workers, record the outcomes.

Every job writes its own file atomically, so a run that is interrupted (Ctrl-C, a killed
process) resumes with the next call and recomputes nothing that had finished. Describe jobs run
first (their features are shared by many home jobs), then home jobs.

Jobs run in isolated worker processes (:mod:`~homebench.evaluation.isolation`), locally or
inside Dask tasks: a job that raises, crashes, hangs past the timeout or runs out of memory is a
failed job, recorded with its cause (:mod:`~homebench.evaluation.failures`), while the others
finish. The run folder is locked and belongs to one config
(:mod:`~homebench.evaluation.run_folder`); its metadata says where the results come from
(:mod:`~homebench.evaluation.provenance`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import shutil
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm import tqdm

from homebench.config import RunConfig, SweptWorld
from homebench.errors import Interrupted, WriteError
from homebench.evaluation.claims_record import stamped_claims
from homebench.evaluation.data_checks import check_source, database_warnings, pattern_notes
from homebench.evaluation.executors import (
    PRELOAD,
    Execution,
    Executor,
    open_executor,
    preload_for,
)
from homebench.evaluation.failures import (
    Failure,
    clear_failure,
    failure_path,
    read_failure,
    record_failure,
)
from homebench.evaluation.isolation import Crash, Limits
from homebench.evaluation.jobs import JobOutcome, read_result, run_describe_job, run_home_job
from homebench.evaluation.plan import DescribeJob, HomeJob, Plan, make_plan
from homebench.evaluation.provenance import (
    record_load_end,
    resolve_config,
    run_sections,
    write_run_metadata,
)
from homebench.evaluation.results import PLAN_FILE, write_plan_index
from homebench.evaluation.run_folder import check_owner, claim_run_folder, lock_run_folder
from homebench.evaluation.sources import Source, prepare_sources

__all__ = ["Execution", "RunOutcome", "run_parallel", "run_plan", "write_run_metadata"]


@dataclass(frozen=True)
class RunOutcome:
    """What a run did: home jobs ``computed`` now and ``reused``; ``failures`` of home jobs of
    this shard (now, or earlier and not retried) and of describe jobs run now; ``pending``:
    home jobs of the plan with neither a result nor a failure here (other shards)."""

    run_dir: Path
    plan: Plan
    computed: int
    reused: int
    failures: tuple[Failure, ...]
    pending: int
    notes: tuple[str, ...] = ()  # how the data compare with their reference sums
    warnings: tuple[str, ...] = ()  # where a database's own files disagree


def _outcomes(
    kind: str, results: Iterator[tuple[Any, JobOutcome | Crash]], total: int, show_progress: bool
) -> Iterator[tuple[Any, JobOutcome]]:
    """Job outcomes as they finish (a crash as the job's error), with a progress bar; a job
    that could not write its file (a full disk) stops the run with a WriteError, as no job
    can succeed in that folder then: no failure is recorded, a rerun computes what is left."""
    with tqdm(total=total, desc=kind, unit="job", disable=not show_progress) as bar:
        for job, result in results:
            if isinstance(result, Crash):
                result = JobOutcome(kind, job.key, result.cause)
            if result.environment:
                raise WriteError(result.error or "a file cannot be written")
            bar.update()
            yield job, result


@contextlib.contextmanager
def interruptible(finished: Callable[[], str], run_dir: Path) -> Iterator[None]:
    """Ctrl-C within the block becomes :class:`~homebench.errors.Interrupted` saying what
    ``finished()`` says ("3 of 10 job(s)") has results in ``run_dir``: each result is
    written whole, so a rerun resumes from there."""
    try:
        yield
    except KeyboardInterrupt:
        raise Interrupted(
            f"interrupted: {finished()} have results in {run_dir}; rerun the same command to resume"
        ) from None


def run_parallel(
    work: Callable[[Any, Path], JobOutcome],
    jobs: Sequence[Any],
    run_dir: Path,
    n_jobs: int,
    label: str,
    show_progress: bool,
    preload: tuple[str, ...] = PRELOAD,
    timeout_s: float | None = None,
    reused: int = 0,
) -> list[JobOutcome]:
    """Run ``work(job, run_dir)`` for every job in ``n_jobs`` isolated local workers (-1: one
    per core) that import ``preload`` first, with a progress bar; the outcomes as they finish
    (a crash, or a job running longer than ``timeout_s``, as the job's error). Ctrl-C stops
    them: Interrupted counting ``reused`` (of the caller's plan) and those that finished."""
    if not jobs:
        return []
    execution = Execution(jobs=n_jobs, timeout_s=timeout_s)
    outcomes: list[JobOutcome] = []

    def finished() -> str:
        done = reused + sum(outcome.error is None for outcome in outcomes)
        return f"{done} of {reused + len(jobs)} job(s)"

    with interruptible(finished, run_dir), open_executor(execution, preload) as executor:
        results = executor.map(work, jobs, run_dir)
        for _, outcome in _outcomes(label, results, len(jobs), show_progress):
            outcomes.append(outcome)
    return outcomes


def _job_label(job: HomeJob | DescribeJob) -> str:
    """What a job is, for messages and failure records."""
    if isinstance(job, DescribeJob):
        images = ", ".join(f"({t.i}, {t.j})" for t in job.images)
        return f"{job.method.label}, images {images}"
    seed = f", seed {job.seed}" if job.seed is not None else ""
    seed += f", style {job.style}" if job.style is not None else ""
    return f"{job.method.label}, {job.condition}, goal ({job.goal.i}, {job.goal.j}){seed}"


def _forget(plan: Plan, jobs: Sequence[HomeJob], run_dir: Path) -> None:
    """--force: remove the results and failure records of ``jobs`` and the plan's features."""
    for job in jobs:
        job.result_path(run_dir).unlink(missing_ok=True)
        clear_failure(run_dir, job.key)
    for key in {job.method.key for job in plan.describe}:
        shutil.rmtree(run_dir / "features" / key, ignore_errors=True)


def _has_failed_pairs(record: dict[str, Any]) -> bool:
    return any(row.get("error") for row in record.get("rows", ()))


def run_plan(
    config: RunConfig,
    config_path: Path,
    execution: Execution,
    *,
    force: bool = False,
    update: bool = False,
    overrides: Sequence[str] = (),
    show_progress: bool = True,
) -> RunOutcome:
    """Prepare the databases, plan, and run every unfinished job (of the shard) of a config.

    A folder that holds another config's run is refused unless ``update`` (it becomes this
    config's run; results whose job keys still match are kept: keys hold everything that
    determines a result) or ``force`` (every job is recomputed). ``overrides``: the
    ``key=value`` settings the config was loaded with, recorded in ``environment.json``."""
    run_dir = Path(config.output)
    preload = preload_for(config.methods)
    fresh = not (run_dir / PLAN_FILE).exists()  # no earlier run here: it will have jobs
    with (
        lock_run_folder(run_dir, shared=execution.shard is not None),
        open_executor(execution, preload) as executor,
    ):
        # the worker server imports while this process plans a fresh run or generates worlds
        if fresh:
            executor.start()
        sources: dict[tuple[str, SweptWorld], Source] = prepare_sources(
            config, execution.jobs, on_generate=executor.start
        )
        checks = {source.identity: check_source(source) for source in sources.values()}
        plan = make_plan(config, sources, config_path)
        with claim_run_folder(run_dir):  # limits are execution settings: no part of it
            claims = stamped_claims(config.claims, run_dir)  # stated before any job runs
            resolved = resolve_config(config, execution, Limits(), claims)
            check_owner(run_dir, resolved, force or update)
            resolved = resolve_config(config, execution, executor.limits, claims)
            extra = run_sections(config, execution, force, plan, sources)
            extra["overrides"]["config"] = list(overrides)
            extra["data_checks"] = {
                identity: check.as_dict() for identity, check in checks.items() if check
            }
            write_run_metadata(config, config_path, run_dir, resolved, extra)
            write_plan_index(plan, run_dir)
        outcome = _run_jobs(plan, run_dir, execution, executor, force, show_progress)
        record_load_end(run_dir, outcome.computed, outcome.reused)
    notes = [note for check in checks.values() if check and (note := check.note())]
    notes += pattern_notes(sources)
    warnings = tuple(database_warnings(sources))
    return dataclasses.replace(outcome, notes=tuple(notes), warnings=warnings)


def _run_jobs(
    plan: Plan,
    run_dir: Path,
    execution: Execution,
    executor: Executor,
    force: bool,
    show_progress: bool,
) -> RunOutcome:
    """Run the shard's home jobs that have no result (nor a failure, unless retrying), after
    the describe jobs of the images they need; record what failed."""
    mine_keys = execution.shard_keys(job.key for job in plan.home)
    mine = [job for job in plan.home if job.key in mine_keys]
    if force:
        _forget(plan, mine, run_dir)
    todo, earlier, reused = [], [], 0
    for job in mine:
        record = read_result(job.result_path(run_dir), job.key)
        failure = read_failure(run_dir, job.key) if record is None else None
        if record is not None and not (execution.retry_failed and _has_failed_pairs(record)):
            reused += 1
        elif failure is not None and not execution.retry_failed:
            earlier.append(failure)
        else:
            todo.append(job)
    needed = {(t, job.method.key) for job in todo for t in (job.goal, *job.currents)}
    describe = [
        DescribeJob(job.method, images)
        for job in plan.describe
        if (images := tuple(t for t in job.images if (t, job.method.key) in needed))
    ]
    failures, computed = [*earlier], 0
    with interruptible(lambda: f"{reused + computed} of {len(mine)} job(s)", run_dir):
        described = executor.map(run_describe_job, describe, run_dir)
        for job, outcome in _outcomes("describe", described, len(describe), show_progress):
            if outcome.error is not None:  # reported; the pairs that miss features fail with it
                failures.append(Failure("describe", job.key, _job_label(job), outcome.error, 1))
        homed = executor.map(run_home_job, todo, run_dir)
        for job, outcome in _outcomes("home", homed, len(todo), show_progress):
            if outcome.error is None:
                clear_failure(run_dir, job.key)
                computed += 1
            else:
                label = _job_label(job)
                failures.append(record_failure(run_dir, "home", job.key, label, outcome.error))
    pending = sum(
        not (job.result_path(run_dir).exists() or failure_path(run_dir, job.key).exists())
        for job in plan.home
        if job.key not in mine_keys
    )
    return RunOutcome(run_dir, plan, computed, reused, tuple(failures), pending)
