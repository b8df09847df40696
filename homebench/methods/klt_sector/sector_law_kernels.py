"""Compiled (numba) kernel of the sector law's ordering filter: the rotation search.

Kept apart from :mod:`homebench.methods.klt_sector.sector_law` so that importing the law (and every
method module, which the command line does to list and check methods) does not import numba,
a third of a second of CPU per process: it is imported when a filter first runs, or by a job
worker server whose methods name this module in ``preload_modules``.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray


@njit(cache=True, nogil=True)
def first_longest_rotation(values: NDArray[np.int64]) -> int:
    """The first start k whose rotation ``values[k:] + values[:k]`` has the longest strictly
    increasing subsequence (patience sorting per rotation, as
    :func:`homebench.methods.klt_sector.sector_law.longest_increasing`)."""
    n = values.size
    tails = np.empty(n, np.int64)
    best_length, best_start = 0, 0
    for start in range(n):
        length = 0
        for k in range(n):
            value = values[(start + k) % n]
            low, high = 0, length
            while low < high:  # bisect_left on tails[:length]
                middle = (low + high) // 2
                if tails[middle] < value:
                    low = middle + 1
                else:
                    high = middle
            tails[low] = value
            length = max(length, low + 1)
        if length > best_length:
            best_length, best_start = length, start
            if length == n:
                break
    return best_start
