"""Where jobs run: isolated local workers, or Dask tasks that run them in isolated workers.

:func:`open_executor` sets up the backend an :class:`Execution` asks for and yields an
:class:`Executor`, whose ``map(work, jobs, run_dir)`` yields ``(job, outcome)`` as jobs finish:
what ``work(job, run_dir)`` returned, or a :class:`~homebench.evaluation.isolation.Crash`. On Dask,
jobs are plain tasks (no retries, no scheduler of ours on the cluster side); each runs its job in
an isolated process of its Dask worker, so a crash or a hang fails that job only, and a local
cluster fails a task at once if its Dask worker dies anyway (``allowed-failures`` 0).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Protocol

from homebench.bounds import workers_problem
from homebench.config import MethodEntry
from homebench.errors import ConfigError
from homebench.evaluation.isolation import (
    Crash,
    Limits,
    WorkerPool,
    default_memory_mb,
    memory_problem,
    run_isolated,
    within_inherited,
)
from homebench.evaluation.jobs import JobOutcome
from homebench.methods import registry

#: What every worker imports before its first job (so that no job's timeout pays for it).
PRELOAD = ("homebench.evaluation.jobs", "homebench.methods")


def preload_for(entries: Iterable[MethodEntry]) -> tuple[str, ...]:
    """What the workers of jobs by a config's method ``entries`` import first: :data:`PRELOAD`
    and each method's ``preload_modules``, the compiled kernels its module imports only when
    they first run (a process that lists or checks methods then never imports numba, and the
    workers of a run that needs it share one import and set-up)."""
    classes = (registry.get(entry.method) for entry in entries)
    extra = (module for cls in classes for module in getattr(cls, "preload_modules", ()))
    return tuple(dict.fromkeys((*PRELOAD, *extra)))


@dataclass(frozen=True)
class Execution:
    """How jobs run: ``jobs`` local workers, or a Dask cluster (``backend="dask"`` at
    ``scheduler``, or a local cluster of ``jobs`` workers); ``shard = (i, n)`` runs only the
    i-th of n deterministic parts of the plan (1-based). Each job may take ``timeout_s`` and its
    worker ``memory_mb`` (None: physical memory / (workers + 1), at least 2 GiB, at most the
    inherited limit: see :func:`~homebench.evaluation.isolation.default_memory_mb`).
    ``retry_failed`` runs jobs that failed before (and jobs with failed pairs) again."""

    jobs: int = 1
    backend: Literal["local", "dask"] = "local"
    scheduler: str | None = None
    shard: tuple[int, int] | None = None
    timeout_s: float | None = None
    memory_mb: int | None = None
    retry_failed: bool = False

    def __post_init__(self) -> None:
        problem = workers_problem(self.jobs)
        if problem:
            raise ConfigError(problem)
        if self.shard is not None and not 1 <= self.shard[0] <= self.shard[1]:
            raise ConfigError(f"shard {self.shard[0]}/{self.shard[1]}: need 1 <= i <= n")
        if self.scheduler is not None and self.backend != "dask":
            raise ConfigError("a scheduler address needs --backend dask")
        if self.scheduler is not None:
            _check_address(self.scheduler)
        if self.timeout_s is not None and self.timeout_s <= 0:
            raise ConfigError("the job timeout must be positive (seconds)")
        problem = memory_problem(self.memory_mb) if self.scheduler is None else ""
        if problem:  # workers here inherit this process's limit; a cluster's have their own
            raise ConfigError(problem)

    @property
    def workers(self) -> int:
        """Local workers (or local Dask workers): ``jobs``, all cores for -1."""
        return (os.cpu_count() or 1) if self.jobs == -1 else self.jobs

    def shard_keys(self, keys: Iterable[str]) -> set[str]:
        """The keys of the plan's jobs ``keys`` that belong to this shard (all without one):
        every N-th of the sorted keys, from the I-th, so N shards of one plan split it into
        parts whose sizes differ by at most one, whatever the keys."""
        ordered = sorted(set(keys))
        if self.shard is None:
            return set(ordered)
        index, count = self.shard
        return set(ordered[index - 1 :: count])


def _check_address(address: str) -> None:
    """ConfigError unless ``address`` is a Dask scheduler's (host and port, "tcp://h:8786");
    whether one answers there is known on connecting."""
    try:
        from distributed.comm.addressing import get_address_host_port
    except ImportError:  # said when the cluster is opened
        return
    try:
        get_address_host_port(address)
    except ValueError as error:
        raise ConfigError(
            f"--scheduler {address!r}: not an address of a Dask scheduler ({error}); give "
            "HOST:PORT or tcp://HOST:PORT"
        ) from None


class Executor(Protocol):
    """Runs jobs (see the module docstring) under ``limits``."""

    limits: Limits

    def start(self) -> None:
        """Set the workers up now, while the caller does other work (else on first use)."""

    def map(
        self, work: Callable[[Any, Path], JobOutcome], jobs: Sequence[Any], run_dir: Path
    ) -> Iterator[tuple[Any, JobOutcome | Crash]]: ...


class _Local:
    """Local isolated workers (their server started by :meth:`start`, else by the first job)."""

    def __init__(self, pool: WorkerPool):
        self.pool, self.limits = pool, pool.limits

    def start(self) -> None:
        self.pool.start_server()

    def map(
        self, work: Callable[[Any, Path], JobOutcome], jobs: Sequence[Any], run_dir: Path
    ) -> Iterator[tuple[Any, JobOutcome | Crash]]:
        return self.pool.map_unordered(work, jobs, (run_dir,))


class _Dask:
    """Dask tasks (no retries), each running its job in an isolated worker of the Dask worker.
    A Dask worker that dies anyway fails its task (KilledWorker), not the run."""

    def __init__(self, client: Any, limits: Limits, preload: tuple[str, ...]):
        self.client, self.limits, self.preload = client, limits, preload

    def start(self) -> None:
        """Nothing: the cluster is up, and its isolated workers start with their tasks."""

    def map(
        self, work: Callable[[Any, Path], JobOutcome], jobs: Sequence[Any], run_dir: Path
    ) -> Iterator[tuple[Any, JobOutcome | Crash]]:
        from dask.distributed import as_completed

        futures = {
            self.client.submit(
                run_isolated, work, (job, run_dir), self.limits, self.preload, pure=False, retries=0
            ): job
            for job in jobs
        }
        for future in as_completed(futures):
            job = futures.pop(future)
            try:
                result = future.result()
            except Exception as error:  # KilledWorker, a lost connection: this job failed
                result = Crash(f"on the Dask cluster: {type(error).__name__}: {error}")
            future.release()
            yield job, result


def _dask_limits(client: Any, execution: Execution) -> Limits:
    """The memory limit of a job on the cluster: as given, else the smallest Dask worker's
    memory per thread (a local cluster's: at most the inherited limit)."""
    memory = execution.memory_mb
    if memory is None:
        workers = client.scheduler_info().get("workers", {}).values()
        shares = [w["memory_limit"] // w["nthreads"] for w in workers if w.get("memory_limit")]
        memory = min(shares) // (1024 * 1024) if shares else default_memory_mb(1)
        if execution.scheduler is None:  # a local cluster's workers inherit this one's limit
            memory = within_inherited(memory)
    return Limits(execution.timeout_s, memory)


@contextlib.contextmanager
def open_executor(execution: Execution, preload: tuple[str, ...] = PRELOAD) -> Iterator[Executor]:
    """The executor ``execution`` asks for; its workers import ``preload`` first."""
    if execution.backend == "local":
        memory = execution.memory_mb or default_memory_mb(execution.workers)
        limits = Limits(execution.timeout_s, memory)
        with WorkerPool(execution.workers, limits, preload) as pool:
            yield _Local(pool)
        return
    try:
        import dask
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError("--backend dask needs `pip install homebench[dask]`") from None
    with contextlib.ExitStack() as stack:
        if execution.scheduler is not None:
            try:
                client = stack.enter_context(Client(execution.scheduler, timeout="10s"))
            except (OSError, TimeoutError) as error:
                raise ConfigError(
                    f"cannot reach the Dask scheduler at {execution.scheduler} ({error})"
                ) from None
        else:
            # a dead worker fails its task at once instead of being retried on others
            with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
                cluster = stack.enter_context(
                    LocalCluster(
                        n_workers=execution.workers,
                        threads_per_worker=1,
                        processes=True,
                        host="127.0.0.1",
                        dashboard_address=None,
                    )  # fmt: skip
                )
            client = stack.enter_context(Client(cluster))
        yield _Dask(client, _dask_limits(client, execution), preload)
