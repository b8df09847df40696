"""The timing rule every benchmark script shares (imported as ``from timing import
cpu_and_wall``; the scripts run from the repository root as ``python benchmarks/bench_x.py``):
process CPU and wall time per call, a floor measured in the same process, the load average,
and a parallel run's speed-up only where other work left it the cores (:func:`speedup`).

A script that times what runs in job workers (a method's ``describe`` and ``home``, a route
trial) first calls :func:`as_in_job_workers`, so that it allocates as they do
(:func:`~homebench.evaluation.worker.keep_freed_memory`): otherwise a method that allocates
large arrays per call pays page faults that depend on what the process allocated before.
Scripts that time generation (its workers keep glibc's defaults) or whole runs (whose main
process does too) leave the defaults.
"""

from __future__ import annotations

import math
import os
import resource
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from homebench.evaluation.worker import keep_freed_memory

_allocator = "glibc's defaults"  # what load() says of this process's allocator


def as_in_job_workers() -> None:
    """Give this process the job workers' allocator settings."""
    global _allocator
    _allocator = (
        "as the job workers" if keep_freed_memory() else "not as the job workers (no glibc)"
    )


def timed(function: Callable[..., Any], *args: Any) -> tuple[Any, tuple[float, float]]:
    """``function(*args)`` and the process CPU and wall seconds it took (one call)."""
    cpu, wall = time.process_time(), time.perf_counter()
    out = function(*args)
    return out, (time.process_time() - cpu, time.perf_counter() - wall)


def cpu_and_wall(function: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Best-of-3 per-call process CPU seconds (``time.process_time``) and wall seconds over
    ``repeats`` calls (after one warm-up call), each the best of its own three rounds."""
    function()
    cpu, wall = [], []
    for _ in range(3):
        cpu_start, wall_start = time.process_time(), time.perf_counter()
        for _ in range(repeats):
            function()
        cpu.append((time.process_time() - cpu_start) / repeats)
        wall.append((time.perf_counter() - wall_start) / repeats)
    return min(cpu), min(wall)


def cpu_with_children() -> float:
    """CPU seconds of this process and of its children that ended (user + system): a run's
    workers count once they have been waited for."""
    own, children = (
        resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
    )
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def print_figures(figures: dict[str, tuple[float, float]], floor: str) -> None:
    """Print (CPU, wall) seconds per call by label as a table in ms, each CPU time also over
    that of the label ``floor`` (a bare library call measured in the same process)."""
    width = max(len(label) for label in figures)
    print(f"  {'per call':{width}s} {'CPU ms':>9s} {'wall ms':>9s} {'/ floor':>8s}")
    base = figures[floor][0]
    for label, (cpu, wall) in figures.items():
        print(f"  {label:{width}s} {1000 * cpu:9.3f} {1000 * wall:9.3f} {cpu / base:8.2f}")


def machine_cpu_s() -> float:
    """CPU seconds the whole machine has spent busy since boot (``/proc/stat``: user, nice,
    system, irq, softirq and steal time over all cores); NaN where there is no such file."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()[1:]
    except OSError:
        return math.nan
    busy = sum(int(fields[k]) for k in (0, 1, 2, 5, 6, 7))
    return busy / os.sysconf("SC_CLK_TCK")


def others_cores(wall: float, own_cpu: float, machine_before: float) -> float:
    """Cores other processes kept busy, on average, over a span of ``wall`` seconds in which
    this process and its children spent ``own_cpu`` seconds (``machine_before``: what
    :func:`machine_cpu_s` said at its start)."""
    return max(0.0, (machine_cpu_s() - machine_before - own_cpu) / wall)


def speedup(serial_wall: float, parallel_wall: float, workers: int, others: float) -> str:
    """``serial_wall / parallel_wall`` as text, with the cores other work kept busy during the
    parallel run (``others``, :func:`others_cores`) beside it; "not measurable" where that
    work held cores the ``workers`` needed (more than the cores less the workers, plus half
    a core): a wall-time ratio then measures the other work as much as the run, and can
    exceed the worker count."""
    cores = len(os.sched_getaffinity(0))
    if math.isnan(others) or others > cores - workers + 0.5:
        return f"not measurable (other work kept {others:.1f} of {cores} cores busy)"
    return f"{serial_wall / parallel_wall:.2f} (other work {others:.1f} of {cores} cores)"


def load() -> str:
    """The 1-, 5- and 15-minute load averages and how this process allocates, for a
    benchmark's report."""
    averages = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"load average {averages}; allocator {_allocator}"
