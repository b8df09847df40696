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
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Literal

from joblib import Parallel, delayed, parallel_config
from pydantic import BaseModel
from tqdm import tqdm

from homebench.config import RunConfig
from homebench.errors import ConfigError
from homebench.evaluation.jobs import JobOutcome, read_result, run_describe_job, run_home_job
from homebench.evaluation.plan import Plan, make_plan
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


def write_run_metadata(config: BaseModel, config_path: Path, run_dir: Path) -> None:
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


@dataclass(frozen=True)
class Execution:
    """How jobs run: ``jobs`` local workers (joblib/loky), or a Dask cluster (``backend="dask"``
    at ``scheduler``, or a local cluster of ``jobs`` workers); ``shard = (i, n)`` runs only the
    i-th of n deterministic parts of the plan (1-based)."""

    jobs: int = 1
    backend: Literal["local", "dask"] = "local"
    scheduler: str | None = None
    shard: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        if self.jobs == 0 or self.jobs < -1:
            raise ConfigError("jobs must be a positive number, or -1 for all cores")
        if self.shard is not None and not 1 <= self.shard[0] <= self.shard[1]:
            raise ConfigError(f"shard {self.shard[0]}/{self.shard[1]}: need 1 <= i <= n")
        if self.scheduler is not None and self.backend != "dask":
            raise ConfigError("a scheduler address needs --backend dask")

    def in_shard(self, key: str) -> bool:
        """Whether the job with ``key`` belongs to this shard (a pure function of the key)."""
        return self.shard is None or int(key[:8], 16) % self.shard[1] == self.shard[0] - 1


@contextmanager
def _workers(execution: Execution) -> Iterator[int]:
    """Set up the backend; yield the n_jobs to give joblib."""
    if execution.backend == "local":
        yield execution.jobs
        return
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError("--backend dask needs `pip install homebench[dask]`") from None
    if execution.scheduler is not None:
        client = Client(execution.scheduler)
    else:
        n = (os.cpu_count() or 1) if execution.jobs == -1 else execution.jobs
        cluster = LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address=None,
        )  # fmt: skip
        client = Client(cluster)
    try:
        with parallel_config(backend="dask"):
            yield -1
    finally:
        client.close()
        if execution.scheduler is None:
            cluster.close()


def run_parallel(
    work: Callable[[Any, Path], JobOutcome],
    jobs: Sequence[Any],
    run_dir: Path,
    n_jobs: int,
    label: str,
    show_progress: bool,
) -> list[JobOutcome]:
    """Run ``work(job, run_dir)`` for every job (in order with n_jobs 1, else in joblib
    workers), with a progress bar; return the outcomes as they finish."""
    if not jobs:
        return []
    if n_jobs == 1:
        results: Iterable[JobOutcome] = (work(job, run_dir) for job in jobs)
    else:
        calls = (delayed(work)(job, run_dir) for job in jobs)
        results = Parallel(n_jobs=n_jobs, return_as="generator_unordered")(calls)
    outcomes = []
    with tqdm(total=len(jobs), desc=label, unit="job", disable=not show_progress) as bar:
        for outcome in results:
            outcomes.append(outcome)
            bar.update()
    return outcomes


def run_plan(
    config: RunConfig,
    config_path: Path,
    execution: Execution,
    *,
    force: bool = False,
    show_progress: bool = True,
) -> RunOutcome:
    """Prepare the databases, plan, and run every unfinished job (of the shard) of a config."""
    run_dir = Path(config.output)
    run_dir.mkdir(parents=True, exist_ok=True)
    sources: dict[str, Source] = prepare_sources(config, execution.jobs)
    plan = make_plan(config, sources, config_path)
    write_run_metadata(config, config_path, run_dir)
    write_plan_index(plan, run_dir)
    mine = [job for job in plan.home if execution.in_shard(job.key)]
    if force:
        for job in mine:
            job.result_path(run_dir).unlink(missing_ok=True)
        for job in plan.describe:
            for task in job.images:
                task.feature_path(run_dir, job.method).unlink(missing_ok=True)
    todo = [job for job in mine if read_result(job.result_path(run_dir), job.key) is None]
    needed = {(t, job.method.key) for job in todo for t in (job.goal, *job.currents)}
    describe = [
        job
        for job in plan.describe
        if any(
            (t, job.method.key) in needed and not t.feature_path(run_dir, job.method).is_file()
            for t in job.images
        )
    ]
    with _workers(execution) as n_jobs:
        described = run_parallel(
            run_describe_job, describe, run_dir, n_jobs, "describe", show_progress
        )
        homed = run_parallel(run_home_job, todo, run_dir, n_jobs, "home", show_progress)
    errors = tuple(outcome for outcome in (*described, *homed) if outcome.error)
    return RunOutcome(run_dir, plan, len(todo), len(mine) - len(todo), errors)
