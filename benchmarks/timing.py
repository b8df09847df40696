"""The timing rule every benchmark script shares (imported as ``from timing import per_call``;
the scripts run from the repository root as ``python benchmarks/bench_x.py``)."""

from __future__ import annotations

import time
from collections.abc import Callable


def per_call(function: Callable[[], object], repeats: int) -> float:
    """Best-of-3 mean seconds per call over ``repeats`` calls (after one warm-up call)."""
    function()
    times = []
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(repeats):
            function()
        times.append((time.perf_counter() - start) / repeats)
    return min(times)
