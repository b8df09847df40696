"""Compiled (numba) kernels of 2D-warping on the scale-plane stack
(:mod:`homebench.methods.warping_2d.planes`): the coarse search over every (alpha, psi) step and
the costs of single (alpha, psi) pairs.

Both return the integers :func:`~homebench.methods.warping_2d.planes.reference_costs` returns.
The coarse search adds about 5 * 10**7 stack entries (20 rho x 288 goal columns x 96 x 96
steps), as Möller's SIMD code does: for one rho and one goal column, the entries of every
(alpha, psi) step are a block of consecutive rows of min-warping's search table (level 0: the
goal columns of consecutive alpha steps side by side, the current columns of consecutive steps
of s = alpha - psi in consecutive rows), added row by row into 16-bit partial sums (8-bit loads
widened and added, which LLVM vectorises). A partial sum takes at most
:data:`COLUMNS_PER_PASS` goal columns, so it cannot overflow (255 each); the passes are added in
32 bits, then the minimum over rho is taken. Three things make those passes fast, each measured
(one coarse search of the default parameters, 288 x 72 views): the three goal columns of one
step added in one pass (explicit 16-bit casts), row indices taken as unsigned (numba then drops
its negative-index branch), and the number of steps a compile-time constant
(:data:`DEFAULT_STEPS`; other numbers run the same code over a run-time number): 3.0 -> 1.4 ms
together.

Compilation, read-only inputs and determinism as :mod:`homebench.methods.min_warping.kernels`:
each kernel compiled for one signature when this module is imported (or loaded from numba's
cache), which a run's worker server does before it forks (warping-2d's ``preload_modules``); no
``fastmath``, no ``parallel`` (integer sums: the order cannot change a result); ``nogil``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numpy.typing import NDArray

from homebench.methods.min_warping.kernels import wrap
from homebench.methods.min_warping.method import STACK_MAX, MinWarping

U8Array = NDArray[np.uint8]
I64Array = NDArray[np.int64]
IntArray = NDArray[np.intp]

#: Goal columns summed in one 16-bit partial sum: their largest total, 257 * 255, fits 16 bits.
COLUMNS_PER_PASS = np.iinfo(np.uint16).max // STACK_MAX
#: The number of alpha and psi steps the coarse search is compiled for (min-warping's default).
DEFAULT_STEPS = MinWarping().n_columns


def _array(dtype: types.Type, ndim: int, readonly: bool = False) -> types.Array:
    return types.Array(dtype, ndim, "C", readonly=readonly)


_TEMPLATE = _array(types.intp, 2, True)
_INDEX = _array(types.intp, 1, True)
#: The one signature each kernel is compiled for.
SIGNATURES = {
    "coarse_costs": _array(types.int64, 2)(
        _array(types.uint8, 2, True), types.intp, _TEMPLATE, _TEMPLATE
    ),
    "pair_costs": _array(types.int64, 1)(
        _array(types.uint8, 3, True), types.boolean, _TEMPLATE, _TEMPLATE, _INDEX, _INDEX
    ),
}


@njit(cache=True, nogil=True)
def _unsigned(i: int) -> np.uint64:
    """A row index (>= 0) as unsigned: numba then drops its negative-index branch when it
    takes the row, which otherwise doubles the time of the 16-bit passes below."""
    return np.uint64(i)


@njit(cache=True, nogil=True)
def _row_offsets(
    table: U8Array, step: int, plane: IntArray, y: IntArray
) -> tuple[IntArray, IntArray]:
    """Where each (rho, goal offset x) reads the table, both (n_rho, n): its row of s = alpha -
    psi is ``first + (start + s) % n_steps``."""
    blocks = table.shape[1]
    n = blocks * step
    n_planes = table.shape[0] // n // step
    first, start = np.empty(plane.shape, dtype=np.intp), np.empty(plane.shape, dtype=np.intp)
    for r in range(plane.shape[0]):
        for x in range(n):
            column = y[r, x]
            first[r, x] = ((x % step) * n_planes + plane[r, x]) * n + (column % step) * blocks
            start[r, x] = column // step
    return first, start


@njit(cache=True, nogil=True)
def _fold(total: NDArray[np.int32], part: NDArray[np.uint16]) -> None:
    """Add the doubled partial sums ``part`` [s, alpha (+ n_steps)] into ``total`` [s, alpha]
    and clear them."""
    blocks = total.shape[1]
    for s in range(total.shape[0]):
        sums, low, high = total[s], part[s, :blocks], part[s, blocks:]
        for a in range(blocks):
            sums[a] += np.int32(low[a]) + np.int32(high[a])
        part[s] = 0


@njit(inline="always")
def _coarse(table: U8Array, step: int, plane: IntArray, y: IntArray, blocks: int) -> I64Array:
    """:func:`coarse_costs` with ``blocks`` (the number of steps, ``table.shape[1]``) passed
    in: inlined where it is a constant, LLVM vectorises the loops over the steps without
    remainder code (a third faster at 96 steps than over a run-time length)."""
    first, start = _row_offsets(table, step, plane, y)
    best = np.full((blocks, blocks), np.iinfo(np.int32).max, dtype=np.int32)  # [s, alpha]
    total = np.empty((blocks, blocks), dtype=np.int32)  # [s, alpha]
    part = np.zeros((blocks, 2 * blocks), dtype=np.uint16)  # [s, alpha (+ blocks)]
    for r in range(plane.shape[0]):
        total[:] = 0
        added = 0  # goal offsets in part: at most COLUMNS_PER_PASS
        for base in range(blocks):
            low, high = blocks - base, 2 * blocks - base
            for x in range(base * step, base * step + step - step % 3, 3):
                if added + 3 > COLUMNS_PER_PASS:
                    _fold(total, part)
                    added = 0
                added += 3
                one, two, three = first[r, x], first[r, x + 1], first[r, x + 2]
                for s in range(blocks):
                    target = part[s, low:high]
                    a_row = table[_unsigned(one + wrap(start[r, x] + s, blocks))]
                    b_row = table[_unsigned(two + wrap(start[r, x + 1] + s, blocks))]
                    c_row = table[_unsigned(three + wrap(start[r, x + 2] + s, blocks))]
                    for a in range(blocks):
                        target[a] = np.uint16(
                            target[a] + np.uint16(a_row[a]) + np.uint16(b_row[a])
                            + np.uint16(c_row[a])
                        )  # fmt: skip
            for x in range(base * step + step - step % 3, base * step + step):
                if added + 1 > COLUMNS_PER_PASS:
                    _fold(total, part)
                    added = 0
                added += 1
                for s in range(blocks):
                    target = part[s, low:high]
                    a_row = table[_unsigned(first[r, x] + wrap(start[r, x] + s, blocks))]
                    for a in range(blocks):
                        target[a] = np.uint16(target[a] + np.uint16(a_row[a]))
        _fold(total, part)
        for s in range(blocks):
            lowest, sums = best[s], total[s]
            for a in range(blocks):  # a ternary, not min(): LLVM vectorises it
                lowest[a] = sums[a] if sums[a] < lowest[a] else lowest[a]
    out = np.empty((blocks, blocks), dtype=np.int64)
    for s in range(blocks):
        for a in range(blocks):
            out[a, wrap(a - s + blocks, blocks)] = best[s, a]
    return out


@njit(SIGNATURES["coarse_costs"], cache=True, nogil=True)
def _coarse_default(table: U8Array, step: int, plane: IntArray, y: IntArray) -> I64Array:
    """:func:`_coarse` for :data:`DEFAULT_STEPS` steps, a compile-time constant."""
    return _coarse(table, step, plane, y, DEFAULT_STEPS)


@njit(SIGNATURES["coarse_costs"], cache=True, nogil=True)
def _coarse_any(table: U8Array, step: int, plane: IntArray, y: IntArray) -> I64Array:
    """:func:`_coarse` for any number of steps."""
    return _coarse(table, step, plane, y, table.shape[1])


def coarse_costs(table: U8Array, step: int, plane: IntArray, y: IntArray) -> I64Array:
    """Cost of every (alpha, psi) step: (n_steps, n_steps), [alpha, psi].

    ``table``: level 0 of min-warping's search table, (step * n_scales * n, n // step): row
    ``(g % step * n_scales + k) * n + (j % step) * n_steps + j // step``, entry ``g // step``
    holds ``D[k, g, j]``. ``plane``, ``y`` (n_rho, n): the template. For goal offset x the goal
    column of alpha step a is ``x + step * a`` (entry ``x // step + a``) and the current column
    of s = a - psi is ``y + step * s`` (row ``... + (y // step + s) % n_steps``,
    :func:`_row_offsets`): each x adds its rows into the doubled partial sums ``[s, c]`` from
    ``c = n_steps - x // step``, whose alpha a is at c = a and c = a + n_steps. The goal
    offsets of one step (one x // step) share those targets: three at a time are added in one
    pass, with explicit 16-bit casts (LLVM then vectorises the pass in 16-bit lanes). The
    default number of steps runs a kernel compiled for it (:data:`DEFAULT_STEPS`), any other
    the same code over a run-time number (one kernel each, so that numba's cache holds one
    entry per kernel, which concurrent processes cannot mix up).
    """
    kernel = _coarse_default if table.shape[1] == DEFAULT_STEPS else _coarse_any
    return kernel(table, step, plane, y)


@njit(SIGNATURES["pair_costs"], cache=True, nogil=True)
def pair_costs(
    stack: U8Array,
    swap: bool,
    plane: IntArray,
    y: IntArray,
    alphas: IntArray,
    psis: IntArray,
) -> NDArray[np.int64]:
    """Costs (m,) of the (alpha, psi) pairs ``alphas``, ``psis`` (m,) in band columns, read
    from ``stack`` (n_scales, n, n) [plane, goal col, current col], or with ``swap`` from the
    swapped views' reading ``D'[k, i, j] = D[n_scales - 1 - k, j, i]``."""
    n_planes, n = stack.shape[0], stack.shape[1]
    out = np.empty(alphas.size, dtype=np.int64)
    for pair in range(alphas.size):
        alpha, turn = alphas[pair] % n, (alphas[pair] - psis[pair]) % n
        best = np.iinfo(np.int64).max
        for r in range(plane.shape[0]):
            total = 0
            for x in range(n):
                g, j, k = wrap(x + alpha, n), wrap(y[r, x] + turn, n), plane[r, x]
                total += stack[n_planes - 1 - k, j, g] if swap else stack[k, g, j]
            best = total if total < best else best
        out[pair] = best
    return out
