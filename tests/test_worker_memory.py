"""Job workers keep freed memory for reuse: a method that allocates and frees the same large
arrays for every pair must not pay the kernel's page faults for them every time."""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import yaml
from conftest import arena_config

from homebench.evaluation.isolation import MIN_DEFAULT_MEMORY_MB, WorkerPool, default_memory_mb

CYCLES = 10


def faults_per_cycle(megabytes: int | None = None) -> float:
    """Minor page faults per cycle of 10 MB arrays (``megabytes`` in all, default 30: a pair's
    arrays) allocated, written and freed (glibc's default trims the heap's top once they are
    free: about 1,000 faults a cycle for 30 MB)."""

    def cycle() -> None:
        arrays = [np.ones(10 << 20, np.uint8) for _ in range((megabytes or 30) // 10)]
        del arrays

    cycle()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(CYCLES):
        cycle()
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / CYCLES


def _in_fresh_process(keep: bool, megabytes: int = 30) -> float:
    """Page faults per cycle (:func:`faults_per_cycle`) in a new process, which first asks to
    keep freed memory when ``keep`` (and fails unless that works)."""
    setup = "from homebench.evaluation.worker import keep_freed_memory as k; assert k(); "
    script = (
        "import sys; sys.path.insert(0, sys.argv[1]); import test_worker_memory as t; "
        f"{setup if keep else ''}print(t.faults_per_cycle({megabytes}))"
    )
    tests = str(Path(__file__).parent)
    command = [sys.executable, "-c", script, tests]
    out = subprocess.run(command, capture_output=True, text=True, check=True)
    return float(out.stdout)


def test_keeping_freed_memory_removes_the_page_faults_of_repeated_large_arrays() -> None:
    assert _in_fresh_process(keep=False) > 500  # the default: the test can fail
    assert _in_fresh_process(keep=True) < 50


def test_a_sift_describe_s_working_set_is_kept_too() -> None:
    """SIFT on a 752 x 564 raw image frees well over 100 MB of pyramids per call; with 64 MB
    kept it paid 33,000 faults per image (141 against 68 ms)."""
    assert _in_fresh_process(keep=True, megabytes=160) < 50


def test_isolated_workers_keep_freed_memory() -> None:
    with WorkerPool(1) as pool:
        ((_, faults),) = pool.map_unordered(faults_per_cycle, [None])
    assert faults < 50


PHYSICAL_MB = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") >> 20


def test_the_default_leaves_room_for_the_main_process() -> None:
    """Two workers at physical memory / 2 each added up to all of it."""
    shares = [w for w in (1, 2, 4) if PHYSICAL_MB // (w + 1) >= MIN_DEFAULT_MEMORY_MB]
    for workers in shares:
        assert default_memory_mb(workers) * (workers + 1) <= PHYSICAL_MB


def _run_limited(
    tmp_path: Path, manifest: Path, limit_mb: int, report: bool = False, **changes: object
) -> tuple:
    """`homebench run` of the arena config (and its PDF report with ``report``) in a process
    with an address-space limit of ``limit_mb`` (as a batch system's ``ulimit -v``): (exit
    code, stderr)."""
    config = arena_config(tmp_path, manifest, methods=[{"method": "warping"}], jobs=1, **changes)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit_mb << 20, limit_mb << 20))

    command = [sys.executable, "-m", "homebench", "run", str(path), "--no-progress"]
    done = subprocess.run(
        [*command, *([] if report else ["--no-report"])],
        capture_output=True, text=True, timeout=240, preexec_fn=limit, check=False,
    )  # fmt: skip
    return done.returncode, done.stderr


#: An inherited limit below the default a worker would otherwise get (all of memory for one).
INHERITED_MB = max(3072, PHYSICAL_MB // 2)


def test_an_inherited_address_space_limit_bounds_the_default(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """Every run under `ulimit -v` broke with "not allowed to raise maximum limit"."""
    code, err = _run_limited(tmp_path, arena_manifest, INHERITED_MB)
    assert code == 0, err
    resolved = json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    assert resolved["worker_memory_mb"] <= INHERITED_MB


def test_a_worker_limit_above_the_inherited_one_says_what_to_set(
    tmp_path: Path, arena_manifest: Path
) -> None:
    code, err = _run_limited(
        tmp_path, arena_manifest, INHERITED_MB, worker_memory_mb=INHERITED_MB + 1024
    )
    assert code == 2
    (line,) = err.splitlines()
    assert line.startswith("homebench: error: ") and "worker_memory_mb" in line
    assert f"at most {INHERITED_MB}" in line


def test_a_run_and_its_report_work_in_2_gib_of_address_space(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """The jobs ran, then the report failed ("Cannot allocate memory"; writing the tables, an
    ImportError): pyarrow's allocator reserved 1 GiB of the 2 for nothing."""
    code, err = _run_limited(tmp_path, arena_manifest, 2048, report=True)
    assert code == 0, err
    assert (tmp_path / "run" / "report" / "report.pdf").is_file()


def test_a_limit_a_run_cannot_work_in_is_said_before_any_work(
    tmp_path: Path, arena_manifest: Path
) -> None:
    code, err = _run_limited(tmp_path, arena_manifest, 1024)
    assert code == 2
    (line,) = err.splitlines()
    assert line.startswith("homebench: error: ulimit -v: this process may map 1,024 MB"), line
    assert not (tmp_path / "run").exists()
