"""Importing this module sets numba up: its compiler and code generator, about 0.4 s of CPU
once per process, which a process otherwise pays at its first compiled call.

Methods with compiled kernels name it in ``preload_modules`` after their kernels, so a worker
server imports it once before it forks. Kernels compiled lazily, at their first call (the
sector law's of klt-sector), then cost a worker what loading them from numba's cache costs
(klt-sector's first call 0.4 -> 0.01 s). Kernel modules compiled for their signatures as they
are imported (min-warping's and warping-2d's) set numba up themselves, in the server: their
workers' first calls pay nothing of it, and a fresh install compiles them there once, while
the run generates its worlds, instead of once in every worker. The function below is compiled
once and then loaded from numba's cache (``cache=True``).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def _nothing() -> int:
    return 0


_nothing()
