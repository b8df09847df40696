"""Imported by the worker server of a run whose methods run numba kernels
(:func:`~homebench.evaluation.executors.preload_for`): numba sets itself up on a process's
first compiled call, which takes half a second or more even for a kernel loaded from its cache.
Done once here, in the server, it is inherited by every worker the server forks (a worker's
first kernel call then takes milliseconds)."""

from __future__ import annotations

from numba import njit


@njit
def _nothing() -> int:
    return 0


_nothing()
