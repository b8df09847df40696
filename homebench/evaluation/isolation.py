"""Jobs in isolated worker processes: a crash, a hang or a memory blow-up fails one job only.

:class:`WorkerPool` keeps N persistent worker processes and feeds them one call at a time through
a socket pair. The workers are forked by one worker server per pool
(:mod:`homebench.evaluation.worker_server`, a fresh interpreter), which imports the ``preload``
modules once before the first worker starts: no worker pays for them again, and no call's
timeout counts them. A worker that dies (a segfault, the kernel's OOM killer) or exceeds the
per-call timeout is killed and replaced; its call comes back as a :class:`Crash` naming the
cause, and the other calls go on. Each worker runs under an address-space limit
(``RLIMIT_AS``), so a runaway allocation raises MemoryError inside the job instead of
exhausting the machine.

The server is a plain subprocess, not a ``multiprocessing`` child, so pools can be opened from
daemonic processes too: :func:`run_isolated` runs a call in one from inside a Dask task, which
gives Dask jobs the same timeout and crash isolation.
"""

from __future__ import annotations

import contextlib
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
from multiprocessing.reduction import send_handle
from typing import Any, TypeVar

from homebench.address_space import ARROW_POOL, inherited_mb
from homebench.errors import HomebenchError

T = TypeVar("T")

#: The default memory limit of a worker is physical memory / (workers + 1), the one left for
#: the main process, but never below this.
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
#: Longest single wait for a message (s): a longer timeout (up to inf) is waited for in turns,
#: as the operating system's wait takes no more than about 290 years.
MAX_WAIT_S = 3600.0


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


def within_inherited(memory_mb: int) -> int:
    """``memory_mb``, or the inherited limit where it is lower: no worker may be given more
    (:func:`~homebench.address_space.inherited_mb`)."""
    inherited = inherited_mb()
    return memory_mb if inherited is None else min(memory_mb, inherited)


def default_memory_mb(workers: int) -> int:
    """Physical memory divided among ``workers`` and the main process, at least
    :data:`MIN_DEFAULT_MEMORY_MB`, at most the inherited limit."""
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // (1024 * 1024)
    return within_inherited(max(MIN_DEFAULT_MEMORY_MB, total // (max(1, workers) + 1)))


def memory_problem(memory_mb: int | None) -> str:
    """Why workers here cannot be limited to ``memory_mb``: it is more than the limit they
    inherit; "" when they can (None, the default, always can)."""
    inherited = inherited_mb()
    if memory_mb is None or inherited is None or memory_mb <= inherited:
        return ""
    return (
        f"worker_memory_mb: {memory_mb} MB is above the {inherited} MB address-space limit "
        f"this process inherited (ulimit -v); set worker_memory_mb to at most {inherited}"
    )


def describe_exit(returncode: int | None, memory_mb: int | None, process: str = "worker") -> str:
    """Why a ``process`` ended, in words (``returncode`` None: a worker that ended with its
    worker server)."""
    if returncode is None:
        return f"{process} ended with its worker server"
    if returncode >= 0:
        return f"{process} exited with code {returncode}"
    number = -returncode
    try:
        name = signal.Signals(number).name
    except ValueError:
        name = f"signal {number}"
    cause = f"{process} killed by {name} ({signal.strsignal(number) or name})"
    if number == signal.SIGKILL:
        limit = f", memory limit {memory_mb} MB per worker" if memory_mb else ""
        cause += f": out of memory? (the kernel's OOM killer sends SIGKILL{limit})"
    return cause


class _Server:
    """The worker server process of a pool and its control connection (protocol: see
    :mod:`homebench.evaluation.worker_server`). It imports ``preload`` while the pool goes on;
    the first worker waits for it."""

    def __init__(self, preload: tuple[str, ...]):
        ours, theirs = socket.socketpair()
        command = [sys.executable, "-m", "homebench.evaluation.worker_server"]
        command += [str(theirs.fileno()), str(os.getpid())]
        environment = {**ARROW_POOL, **os.environ, **dict.fromkeys(THREAD_LIMITS, "1")}
        self.process = subprocess.Popen(command, pass_fds=[theirs.fileno()], env=environment)
        theirs.close()
        self.control = Connection(ours.detach())
        self.ended: dict[int, int] = {}  # worker pid -> exit code, not yet asked for
        self.control.send((sys.path, preload))
        self.ready = False

    def start(self, memory_mb: int | None) -> tuple[int, Connection]:
        """A new worker limited to ``memory_mb`` (None: no limit): its pid and connection."""
        if not self.ready:
            self._expect("ready")
            self.ready = True
        ours, theirs = socket.socketpair()
        with theirs, contextlib.suppress(OSError):  # the server has ended: _expect says how
            self.control.send(("start", memory_mb or 0))
            send_handle(self.control, theirs.fileno(), self.process.pid)
        return self._expect("started"), Connection(ours.detach())

    def stop(self, pid: int) -> int | None:
        """Kill worker ``pid`` if it still runs; its exit code (None: the server has ended,
        which ended the worker too)."""
        try:
            if pid not in self.ended:
                self.control.send(("kill", pid))
            while pid not in self.ended:
                self._receive()
        except (OSError, WorkerStartError):
            return None
        return self.ended.pop(pid)

    def close(self) -> None:
        """End the server (which kills the workers it still has) and wait for it; a server
        still importing has no worker and is killed at once."""
        self.control.close()
        if not self.ready:
            self.process.kill()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()

    def _expect(self, kind: str) -> int:
        """Read messages until one of ``kind``; its pid."""
        while True:
            message = self._receive()
            if message[0] == kind:
                return message[1]

    def _receive(self) -> tuple:
        """The next message (noting the workers' ends); WorkerStartError if the server has
        ended."""
        try:
            message = self.control.recv()
        except (EOFError, OSError):
            returncode = self.process.wait()
            raise WorkerStartError(
                f"the worker server ended: {describe_exit(returncode, None, 'it')}; "
                "see the messages above"
            ) from None
        if message[0] == "ended":
            self.ended[message[1]] = message[2]
        return message


class _Worker:
    """One worker process, its connection, and the call it is running (if any)."""

    def __init__(self, server: _Server, memory_mb: int | None):
        self.server = server
        self.pid, self.conn = server.start(memory_mb)
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

    def stop(self) -> int | None:
        """Kill the process if it still runs; its exit code (None: unknown, see
        :meth:`_Server.stop`)."""
        self.conn.close()
        return self.server.stop(self.pid)


class WorkerPool:
    """``size`` persistent isolated workers, started when calls need them, forked from a worker
    server that imports the ``preload`` modules first; a context manager (leaving it ends the
    workers and the server)."""

    def __init__(self, size: int, limits: Limits = Limits(), preload: tuple[str, ...] = ()):
        if size < 1:
            raise ValueError("a worker pool needs at least one worker")
        self.size, self.limits, self.preload = size, limits, preload
        self.workers: list[_Worker] = []
        self.server: _Server | None = None

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        for w in self.workers:
            w.conn.close()
        self.workers = []
        if self.server is not None:
            self.server.close()
            self.server = None

    def start_server(self) -> None:
        """Start the worker server now, so that it imports the preload modules while the
        caller does other work (the first call starts it otherwise)."""
        self._server()

    def map_unordered(
        self, function: Callable[..., Any], items: Iterable[T], args: tuple = ()
    ) -> Iterator[tuple[T, Any]]:
        """``(item, function(item, *args))`` as calls finish, or ``(item, Crash)`` for a call
        whose worker died, timed out or raised past the function."""
        pending = deque(items)
        while pending or any(w.busy for w in self.workers):
            running = sum(w.busy for w in self.workers)
            while len(self.workers) < min(self.size, running + len(pending)):
                self.workers.append(_Worker(self._server(), self.limits.memory_mb))
            for w in self.workers:
                if w.ready and not w.busy and pending:
                    item = pending.popleft()
                    if not w.assign(item, function, (item, *args)):
                        pending.appendleft(item)  # found dead below, then replaced
            yield from self._collect()

    def _server(self) -> _Server:
        """The pool's worker server: started on first use, and again if it has ended after
        serving (one that ended before it was ready fails the next start, saying how)."""
        server = self.server
        if server is not None and server.ready and server.process.poll() is not None:
            server.close()
            self.server = None
        if self.server is None:
            self.server = _Server(self.preload)
        return self.server

    def _collect(self) -> Iterator[tuple[Any, Any]]:
        """Wait for a message, a dead worker or the next timeout; yield the calls that ended."""
        limit = self.limits.timeout_s
        starts = [w.started for w in self.workers if w.busy]
        timeout = None if limit is None or not starts else min(starts) + limit - time.monotonic()
        if timeout is not None:
            timeout = min(max(0.0, timeout), MAX_WAIT_S)
        ready = wait([w.conn for w in self.workers], timeout)
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
