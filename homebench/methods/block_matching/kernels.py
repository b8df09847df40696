"""Compiled (numba) block search of block-matching: the sum of squared differences of every
block at every candidate displacement, and the best candidate's horizontal displacement.

Bit for bit what numpy's search (``np.sum((shifted - block) ** 2, axis=(0, 2))`` per candidate
over a Python loop, 18 ms a pair; tests/test_block_matching.py keeps it as the reference) gives,
in 0.6 ms: the same float64 operations in the same order, each rounded once (no ``fastmath``: no
reassociation, no fused multiply-add). numpy sums a block row by row, the rows one after the
other, each row's squared differences by its pairwise summation: below 8 values one after the
other; from 8 to 128, in 8 running sums, then their tree, then the rest (it halves longer rows:
block-matching's ``block_size`` stays below, see
:data:`~homebench.methods.block_matching.method.LARGEST_BLOCK`). Here the sums run elementwise over
the
horizontal displacements (contiguous columns of a goal row), so vector width does not change a
result; then the candidates are scanned in
:func:`~homebench.methods.block_matching.method.displacements`' order and the first smallest cost
wins,
as ``argmin``.

Compilation as :mod:`homebench.methods.min_warping.kernels`: one signature, compiled (or loaded
from numba's cache) when the module is imported, which block-matching's first search does (so
that importing the method does not import numba) and a run's worker server does before it
forks (``preload_modules``); inputs are declared read-only (feature files are read into
read-only arrays; writable ones convert). No ``parallel``; ``nogil``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

#: numpy's pairwise summation adds fewer values than this one after the other, more in this
#: many running sums.
_SEQUENTIAL = 8


def _array(dtype: types.Type, ndim: int, readonly: bool = False) -> types.Array:
    return types.Array(dtype, ndim, "C", readonly=readonly)


_BAND = _array(types.float64, 2, True)
#: The one signature the search is compiled for.
SIGNATURE = _array(types.intp, 1)(
    _BAND, _BAND, types.intp, _array(types.intp, 1, True), _array(types.intp, 2, True)
)


@njit(cache=True, nogil=True)
def _row_sums(
    source: FloatArray,
    values: FloatArray,
    squares: FloatArray,
    partial: FloatArray,
    out: FloatArray,
) -> None:
    """``out[x] =`` numpy's sum of ``(source[l + x] - values[l]) ** 2`` over l (``values``:
    one block row, at most 128 values), elementwise over x; ``squares`` (rows, width)
    and ``partial`` (8, width): scratch."""
    count, width = values.size, out.size
    if count < _SEQUENTIAL:  # one after the other
        out[:] = -0.0
        for i in range(count):
            for x in range(width):
                d = source[i + x] - values[i]
                out[x] += d * d
        return
    for i in range(count):  # 8 running sums, their tree, then the rest
        for x in range(width):
            d = source[i + x] - values[i]
            squares[i, x] = d * d
    partial[:] = squares[:_SEQUENTIAL]
    end = count - count % _SEQUENTIAL
    for i in range(_SEQUENTIAL, end, _SEQUENTIAL):
        for t in range(_SEQUENTIAL):
            for x in range(width):
                partial[t, x] += squares[i + t, x]
    for x in range(width):
        out[x] = ((partial[0, x] + partial[1, x]) + (partial[2, x] + partial[3, x])) + (
            (partial[4, x] + partial[5, x]) + (partial[6, x] + partial[7, x])
        )
    for i in range(end, count):
        for x in range(width):
            out[x] += squares[i, x]


@njit(SIGNATURE, cache=True, nogil=True)
def block_flow(
    current: FloatArray,
    goal: FloatArray,
    block_size: int,
    centres: IntArray,
    candidates: IntArray,
) -> IntArray:
    """As :func:`homebench.methods.block_matching.method.block_flow` (its arguments; (m,) whole
    columns), bit for bit."""
    rows, n = current.shape
    top = (rows - block_size) // 2
    half = block_size // 2
    reach, low, high = 0, 0, 0  # the largest |dx|; the smallest and largest dy
    for c in range(candidates.shape[0]):
        reach = max(reach, abs(candidates[c, 1]))
        low, high = min(low, candidates[c, 0]), max(high, candidates[c, 0])
    width = 2 * reach + 1
    # goal rows widened so that a block column plus any dx is one index: column p - half - reach
    extended = np.empty((rows, n + block_size - 1 + 2 * reach))
    for r in range(rows):
        for p in range(extended.shape[1]):
            extended[r, p] = goal[r, (p - half - reach) % n]
    squares, block = np.empty((block_size, width)), np.empty((block_size, block_size))
    partial, row_sum = np.empty((_SEQUENTIAL, width)), np.empty(width)
    cost = np.empty((high - low + 1, width))
    flow = np.empty(centres.size, dtype=np.intp)
    for j in range(centres.size):
        start = centres[j] % n  # block column col sits at centres[j] - half + col
        for k in range(block_size):
            for col in range(block_size):
                block[k, col] = current[top + k, (start - half + col) % n]
        for dy in range(low, high + 1):
            total = cost[dy - low]
            total[:] = 0.0
            for k in range(block_size):
                source = extended[top + dy + k, start:]
                _row_sums(source, block[k], squares, partial, row_sum)
                for x in range(width):
                    total[x] += row_sum[x]
        best = 0
        for c in range(candidates.shape[0]):
            here = cost[candidates[c, 0] - low, candidates[c, 1] + reach]
            if here < cost[candidates[best, 0] - low, candidates[best, 1] + reach]:
                best = c
        flow[j] = candidates[best, 1]
    return flow
