"""Job workers keep freed memory for reuse: a method that allocates and frees the same large
arrays for every pair must not pay the kernel's page faults for them every time."""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

import numpy as np

from homebench.evaluation.isolation import WorkerPool

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
    script = (
        "import sys; sys.path.insert(0, sys.argv[1]); import test_worker_memory as t; "
        "from homebench.evaluation.worker import keep_freed_memory; "
        f"assert {not keep} or keep_freed_memory(); print(t.faults_per_cycle({megabytes}))"
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
