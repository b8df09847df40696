"""Running a plan: skip what is finished, run the rest in joblib workers, collect the outcomes.

Every job writes its own file atomically, so a run that is interrupted (Ctrl-C, a killed
process) resumes with the next call and recomputes nothing that had finished. Describe jobs run
first (their features are shared by many home jobs), then home jobs.
"""

from __future__ import annotations

import json
import os
import platform
import socket
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from joblib import Parallel, delayed
from tqdm import tqdm

from homebench.config import RunConfig
from homebench.evaluation.jobs import JobOutcome, read_result, run_describe_job, run_home_job
from homebench.evaluation.plan import DescribeJob, HomeJob, Plan, make_plan
from homebench.evaluation.results import write_plan_index
from homebench.evaluation.sources import Source, prepare_sources
from homebench.fileio import write_text_atomic
from homebench.hashing import canonical_json

PACKAGES = ("homebench", "numpy", "opencv-contrib-python-headless", "pandas", "joblib", "pydantic")


@dataclass(frozen=True)
class RunOutcome:
    run_dir: Path
    plan: Plan
    computed: int  # home jobs computed in this call
    reused: int  # home jobs found finished
    failures: tuple[JobOutcome, ...]


def _versions() -> dict[str, str]:
    found = {"python": sys.version.split()[0]}
    for name in PACKAGES:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = "not installed"
    return found


def write_run_metadata(config: RunConfig, config_path: Path, run_dir: Path) -> None:
    """The resolved config, package versions and host, beside the results."""
    resolved = config.model_dump(mode="json")
    write_text_atomic(run_dir / "config.resolved.json", json.dumps(resolved, indent=2) + "\n")
    environment = {
        "config_file": str(config_path),
        "config_hash": canonical_json(resolved),
        "versions": _versions(),
        "host": socket.gethostname(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "started": datetime.now(UTC).isoformat(timespec="seconds"),
    }
    write_text_atomic(run_dir / "environment.json", json.dumps(environment, indent=2) + "\n")


def _run_parallel(
    work: Callable[..., JobOutcome],
    jobs: Sequence[DescribeJob] | Sequence[HomeJob],
    run_dir: Path,
    n_jobs: int,
    label: str,
    show_progress: bool,
) -> list[JobOutcome]:
    if not jobs:
        return []
    calls: Iterable[Any] = (delayed(work)(job, run_dir) for job in jobs)
    if n_jobs == 1:
        results: Iterable[JobOutcome] = (work(job, run_dir) for job in jobs)
    else:
        results = Parallel(n_jobs=n_jobs, return_as="generator_unordered")(calls)
    outcomes = []
    with tqdm(total=len(jobs), desc=label, unit="job", disable=not show_progress) as bar:
        for outcome in results:
            outcomes.append(outcome)
            bar.update()
    return outcomes


def pending_home_jobs(plan: Plan, run_dir: Path) -> list[HomeJob]:
    """Home jobs without a valid result file."""
    return [job for job in plan.home if read_result(job.result_path(run_dir), job.key) is None]


def run_plan(
    config: RunConfig,
    config_path: Path,
    *,
    jobs: int | None = None,
    force: bool = False,
    show_progress: bool = True,
) -> RunOutcome:
    """Prepare the databases, plan, and run every unfinished job of a config."""
    n_jobs = jobs if jobs is not None else config.jobs
    run_dir = Path(config.output)
    run_dir.mkdir(parents=True, exist_ok=True)
    sources: dict[str, Source] = prepare_sources(config, n_jobs)
    plan = make_plan(config, sources, config_path)
    write_run_metadata(config, config_path, run_dir)
    write_plan_index(plan, run_dir)
    if force:
        for job in plan.home:
            job.result_path(run_dir).unlink(missing_ok=True)
        for job in plan.describe:
            for task in job.images:
                task.feature_path(run_dir, job.method).unlink(missing_ok=True)
    todo = pending_home_jobs(plan, run_dir)
    needed = {(t, job.method.key) for job in todo for t in (job.goal, *job.currents)}
    describe = [
        job
        for job in plan.describe
        if any(
            (t, job.method.key) in needed and not t.feature_path(run_dir, job.method).is_file()
            for t in job.images
        )
    ]
    described = _run_parallel(
        run_describe_job, describe, run_dir, n_jobs, "describe", show_progress
    )
    homed = _run_parallel(run_home_job, todo, run_dir, n_jobs, "home", show_progress)
    errors = tuple(outcome for outcome in (*described, *homed) if outcome.error)
    return RunOutcome(run_dir, plan, len(todo), len(plan.home) - len(todo), errors)
