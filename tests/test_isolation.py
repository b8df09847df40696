"""Isolated workers: each call runs in a worker process forked from one worker server, which
imported the preload modules once; a worker that crashes, exits or hangs fails its call only,
says how it ended, and is replaced; closing the pool ends every process it started."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest

from homebench.evaluation.isolation import Crash, Limits, WorkerPool, WorkerStartError

PRELOAD_MODULE = "homebench_test_preload_counter"


def _pids(_: object = None) -> tuple[int, int]:
    """The worker's process id and its parent's."""
    return os.getpid(), os.getppid()


def _square(x: int) -> int:
    return x * x


def _end(how: str) -> None:
    """End the worker: with an exit code, a signal, or by hanging."""
    if how == "exit":
        os._exit(3)
    if how == "hang":
        time.sleep(600)
    os.kill(os.getpid(), getattr(signal, how))


def _exists(pid: int) -> bool:
    """Whether process ``pid`` exists (a worker's server waits for it as soon as it ends)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.fixture
def counting_preload(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A preload module that appends its importer's pid to a file; that file."""
    log = tmp_path / "imports.txt"
    (tmp_path / f"{PRELOAD_MODULE}.py").write_text(
        f"import os\nwith open({str(log)!r}, 'a') as f:\n    f.write(f'{{os.getpid()}}\\n')\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    return log


def test_workers_are_forked_from_one_server_that_imported_the_preload_once(
    counting_preload: Path,
) -> None:
    with WorkerPool(2, preload=(PRELOAD_MODULE,)) as pool:
        first = dict(pool.map_unordered(_pids, range(6)))
        crashed = dict(pool.map_unordered(_end, ["exit"]))
        after = dict(pool.map_unordered(_pids, range(4)))
    assert isinstance(crashed["exit"], Crash)
    workers = {pid for pid, _ in [*first.values(), *after.values()]}
    servers = {parent for _, parent in [*first.values(), *after.values()]}
    assert len(workers) >= 2 and len(servers) == 1 and os.getpid() not in servers
    importers = counting_preload.read_text().split()
    assert importers == [str(servers.pop())], "the preload is imported once, by the server"


def test_a_worker_that_exits_or_is_killed_fails_its_call_and_is_replaced() -> None:
    calls = ["exit", "SIGKILL", "SIGSEGV", "SIGTERM"]
    with WorkerPool(2) as pool:
        results = dict(pool.map_unordered(_end, calls))
        squares = dict(pool.map_unordered(_square, range(5)))
    assert results["exit"] == Crash("worker exited with code 3")
    assert results["SIGKILL"].cause.startswith("worker killed by SIGKILL")
    assert "out of memory?" in results["SIGKILL"].cause
    assert results["SIGSEGV"].cause.startswith("worker killed by SIGSEGV")
    assert results["SIGTERM"].cause.startswith("worker killed by SIGTERM")
    assert squares == {x: x * x for x in range(5)}


def test_a_hanging_call_times_out_and_its_worker_is_killed() -> None:
    with WorkerPool(1, Limits(timeout_s=1)) as pool:
        ((_, (pid, _)),) = pool.map_unordered(_pids, [None])
        start = time.monotonic()
        ((_, result),) = pool.map_unordered(_end, ["hang"])
        assert time.monotonic() - start < 30
        assert result == Crash("timed out after 1 s")
        assert not _exists(pid)
        ((_, square),) = pool.map_unordered(_square, [7])
    assert square == 49


def test_closing_the_pool_ends_the_workers_and_their_server() -> None:
    with WorkerPool(2) as pool:
        seen = dict(pool.map_unordered(_pids, range(4)))
    processes = {pid for pair in seen.values() for pid in pair} - {os.getpid()}
    assert len(processes) >= 2  # the server and at least one worker
    assert not any(_exists(pid) for pid in processes), "closing waits for every process"


def test_a_memory_limit_below_what_a_worker_already_maps_is_a_start_error() -> None:
    with (
        pytest.raises(WorkerStartError, match="could not start"),
        WorkerPool(1, Limits(memory_mb=16)) as pool,
    ):
        list(pool.map_unordered(_square, [2]))


def _kill_server(_: object = None) -> None:
    """Kill the worker's server (the kernel then kills the worker with it)."""
    os.kill(os.getppid(), signal.SIGKILL)
    time.sleep(600)


def test_a_dead_server_fails_its_workers_calls_and_a_new_one_takes_over() -> None:
    with WorkerPool(1) as pool:
        ((_, (_, first_server)),) = pool.map_unordered(_pids, [None])
        ((_, result),) = pool.map_unordered(_kill_server, [None])
        ((_, (_, second_server)),) = pool.map_unordered(_pids, [None])
    assert result == Crash("worker ended with its worker server")
    assert second_server != first_server


def test_a_started_server_imports_before_the_first_call_and_serves_it(
    counting_preload: Path,
) -> None:
    with WorkerPool(1, preload=(PRELOAD_MODULE,)) as pool:
        pool.start_server()
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (
            counting_preload.exists() and counting_preload.read_text().endswith("\n")
        ):
            time.sleep(0.05)
        importers = counting_preload.read_text().split()  # before any call
        ((_, (_, server)),) = pool.map_unordered(_pids, [None])
    assert importers == [str(server)]


def test_closing_a_pool_whose_server_is_still_importing_ends_it_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run that needs no worker (every job done) does not wait for the server's imports."""
    (tmp_path / "homebench_test_slow_preload.py").write_text("import time\ntime.sleep(600)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    pool = WorkerPool(1, preload=("homebench_test_slow_preload",))
    pool.start_server()
    assert pool.server is not None
    server = pool.server.process
    start = time.monotonic()
    pool.close()
    assert time.monotonic() - start < 30
    assert server.poll() is not None


def test_a_server_that_cannot_import_its_preload_is_a_start_error_said_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """Started early (while a run generates its worlds), a server whose preload fails is not
    started again by the first call: the error is the broken setup's, once."""
    (tmp_path / "homebench_test_broken_preload.py").write_text("raise ImportError('broken')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with WorkerPool(1, preload=("homebench_test_broken_preload",)) as pool:
        pool.start_server()
        assert pool.server is not None
        pool.server.process.wait(timeout=60)
        with pytest.raises(WorkerStartError, match="worker server ended"):
            list(pool.map_unordered(_square, [2]))
    assert capfd.readouterr().err.count("ImportError: broken") == 1
