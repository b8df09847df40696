"""Jobs in isolated worker processes: a crash, a hang or a memory blow-up fails one job only.

:class:`WorkerPool` keeps N persistent worker processes (fresh interpreters, see
:mod:`homebench.evaluation.worker`) and feeds them one call at a time through a socket pair.
Each worker imports the ``preload`` modules before it takes its first call, so a call's timeout
counts the call only. A worker that dies (a segfault, the kernel's OOM killer) or exceeds the
per-call timeout is killed and replaced; its call comes back as a :class:`Crash` naming the
cause, and the other calls go on. Each worker runs under an address-space limit (``RLIMIT_AS``),
so a runaway allocation raises MemoryError inside the job instead of exhausting the machine.

Workers are plain subprocesses, not ``multiprocessing`` children, so they can be started from
daemonic processes too: :func:`run_isolated` runs a call in one from inside a Dask task, which
gives Dask jobs the same timeout and crash isolation.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any, TypeVar

from homebench.errors import HomebenchError

T = TypeVar("T")

#: The default memory limit of a worker is physical memory / workers, but never below this.
MIN_DEFAULT_MEMORY_MB = 2048
#: One thread per numeric library in a worker (set before they load).
THREAD_LIMITS = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "BLIS_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)


class WorkerStartError(HomebenchError):
    """A worker process died before it was ready (a broken environment, not a job's fault)."""


@dataclass(frozen=True)
class Limits:
    """Per-call limits: ``timeout_s`` and the worker's ``memory_mb`` (None: no limit)."""

    timeout_s: float | None = None
    memory_mb: int | None = None


@dataclass(frozen=True)
class Crash:
    """A call that did not return a result, and why."""

    cause: str


def default_memory_mb(workers: int) -> int:
    """Physical memory divided among ``workers``, at least :data:`MIN_DEFAULT_MEMORY_MB`."""
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // (1024 * 1024)
    return max(MIN_DEFAULT_MEMORY_MB, total // max(1, workers))


def describe_exit(returncode: int | None, memory_mb: int | None) -> str:
    """Why a worker process ended, in words."""
    if returncode is None or returncode >= 0:
        return f"worker exited with code {returncode}"
    number = -returncode
    try:
        name = signal.Signals(number).name
    except ValueError:
        name = f"signal {number}"
    cause = f"worker killed by {name} ({signal.strsignal(number) or name})"
    if number == signal.SIGKILL:
        limit = f", memory limit {memory_mb} MB per worker" if memory_mb else ""
        cause += f": out of memory? (the kernel's OOM killer sends SIGKILL{limit})"
    return cause


class _Worker:
    """One worker process, its connection, and the call it is running (if any)."""

    def __init__(self, memory_mb: int | None, preload: tuple[str, ...]):
        ours, theirs = socket.socketpair()
        command = [sys.executable, "-m", "homebench.evaluation.worker", str(theirs.fileno())]
        command += [str(memory_mb or 0), str(os.getpid())]
        environment = {**os.environ, **dict.fromkeys(THREAD_LIMITS, "1")}
        self.process = subprocess.Popen(command, pass_fds=[theirs.fileno()], env=environment)
        theirs.close()
        self.conn = Connection(ours.detach())
        self.conn.send((sys.path, preload))
        self.ready = self.busy = False
        self.item: Any = None
        self.started = 0.0

    def assign(self, item: Any, function: Callable[..., Any], args: tuple) -> bool:
        """Send a call; False if the worker is gone (the call was not started)."""
        try:
            self.conn.send((function, args))
        except OSError:
            return False
        self.item, self.busy, self.started = item, True, time.monotonic()
        return True

    def stop(self) -> int:
        """Kill the process if it still runs; its return code."""
        self.conn.close()
        if self.process.poll() is None:
            self.process.kill()
        return self.process.wait()


class WorkerPool:
    """``size`` persistent isolated workers, started when calls need them, each importing the
    ``preload`` modules before its first call; a context manager (leaving it kills them)."""

    def __init__(self, size: int, limits: Limits = Limits(), preload: tuple[str, ...] = ()):
        if size < 1:
            raise ValueError("a worker pool needs at least one worker")
        self.size, self.limits, self.preload = size, limits, preload
        self.workers: list[_Worker] = []

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        for w in self.workers:
            w.stop()
        self.workers = []

    def map_unordered(
        self, function: Callable[..., Any], items: Iterable[T], args: tuple = ()
    ) -> Iterator[tuple[T, Any]]:
        """``(item, function(item, *args))`` as calls finish, or ``(item, Crash)`` for a call
        whose worker died, timed out or raised past the function."""
        pending = deque(items)
        while pending or any(w.busy for w in self.workers):
            running = sum(w.busy for w in self.workers)
            while len(self.workers) < min(self.size, running + len(pending)):
                self.workers.append(_Worker(self.limits.memory_mb, self.preload))
            for w in self.workers:
                if w.ready and not w.busy and pending:
                    item = pending.popleft()
                    if not w.assign(item, function, (item, *args)):
                        pending.appendleft(item)  # found dead below, then replaced
            yield from self._collect()

    def _collect(self) -> Iterator[tuple[Any, Any]]:
        """Wait for a message, a dead worker or the next timeout; yield the calls that ended."""
        limit = self.limits.timeout_s
        starts = [w.started for w in self.workers if w.busy]
        timeout = None if limit is None or not starts else min(starts) + limit - time.monotonic()
        ready = wait([w.conn for w in self.workers], None if timeout is None else max(0, timeout))
        now = time.monotonic()
        for w in list(self.workers):
            ended = None
            if w.conn in ready:
                ended = self._receive(w)
            elif limit is not None and w.busy and now - w.started >= limit:
                ended = self._drop(w, f"timed out after {limit:g} s")
            if ended is not None:
                yield ended

    def _receive(self, w: _Worker) -> tuple[Any, Any] | None:
        try:
            kind, value = w.conn.recv()
        except (EOFError, OSError):
            return self._drop(w, None)
        if kind == "ready":
            w.ready = True
            return None
        w.busy = False
        return w.item, value if kind == "ok" else Crash(value)

    def _drop(self, w: _Worker, cause: str | None) -> tuple[Any, Crash] | None:
        """Stop ``w`` and forget it; its call, if any, failed with ``cause`` (default: how the
        process ended). A worker that dies before it is ready means a broken setup."""
        returncode = w.stop()
        self.workers.remove(w)
        if not w.ready:
            raise WorkerStartError(
                f"a worker process could not start ({describe_exit(returncode, None)}); "
                "see the messages above"
            )
        if not w.busy:
            return None
        return w.item, Crash(cause or describe_exit(returncode, self.limits.memory_mb))


_LOCAL = threading.local()


def run_isolated(
    function: Callable[..., Any], args: tuple, limits: Limits, preload: tuple[str, ...] = ()
) -> Any:
    """``function(*args)`` in a persistent isolated worker of the calling thread (for Dask
    tasks): its result, or a :class:`Crash`."""
    pool = getattr(_LOCAL, "pool", None)
    if pool is None or (pool.limits, pool.preload) != (limits, preload):
        if pool is not None:
            pool.close()
        pool = _LOCAL.pool = WorkerPool(1, limits, preload)
    ((_, result),) = pool.map_unordered(_call, [None], (function, args))
    return result


def _call(_: None, function: Callable[..., Any], args: tuple) -> Any:
    return function(*args)
