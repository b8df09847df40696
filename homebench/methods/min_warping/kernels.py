"""Compiled (numba) kernels of min-warping: the 8-bit column-distance stack and the searches.

The pure-numpy reading in :mod:`homebench.methods.min_warping.method` is the reference; these
kernels
return the same integers (the search) or the same stack up to one unit of the 8-bit scale (the
distances: float32 sums in a fixed order against numpy's float64). Why numba: the search takes
the minimum of about 10**8 small integers (288 goal columns x 96 x 96 steps x about 50
admissible pairs); numpy needs index arrays as large as that (or a Python loop over alphas), a
compiled loop over contiguous 8-bit rows does it in SIMD registers, as Möller's C++ does.
Beyond his code, the pairs of one goal column are runs of consecutive current columns on one
plane (2,095 runs for 14,923 pairs at 288 columns), and a table of minima over power-of-two
windows of current columns answers a run with two look-ups.

Every kernel writes into arrays its caller passes (a thread's
:class:`~homebench.methods.min_warping.search.Workspace`): a call allocates nothing large, so
it pays no page faults whatever the process's allocator does with freed memory; each kernel
overwrites every entry it later reads, so a result never depends on what a buffer held before.

Determinism: no ``fastmath`` (no reassociation, no fused multiply-add), no ``parallel``; float
sums run elementwise over the current columns, each in a fixed order over the rows, so vector
width does not change a result; the search is integer. ``nogil`` lets threads share a process.

Compilation: each kernel is compiled for its one signature (:data:`SIGNATURES`) when this module
is imported, not at its first call, and ``cache=True`` keeps the machine code in this package's
``__pycache__`` (numba writes it atomically; without write access it falls back to a user cache
directory). A run's worker server imports this module before it forks the workers (the method's
``preload_modules``), while the run plans and generates its worlds: the first run on a fresh
install compiles once there (3-4 s of CPU) instead of once in every worker, and later
processes load the cache. Inputs are declared read-only (feature files are read into read-only
arrays; writable ones convert), and an argument of another type is a TypeError, never a
silent compilation in a worker. :mod:`~homebench.methods.min_warping.method` imports this module at
its first compiled search, so that a process that only lists or checks methods does not import
numba (a third of a second of CPU); warping-2d's scale-plane scheme imports it for the stack
and its table (loading the five kernels takes 0.04 s).
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numpy.typing import NDArray

from homebench.methods.min_warping.method import STACK_MAX

U8Array = NDArray[np.uint8]
IntArray = NDArray[np.intp]


def _array(dtype: types.Type, ndim: int, readonly: bool = False) -> types.Array:
    return types.Array(dtype, ndim, "C", readonly=readonly)


_F32_IN, _F32_OUT = _array(types.float32, 3, True), _array(types.float32, 3)
_SIZES = _array(types.float32, 2, True)
_STACK_IN, _STACK_OUT = _array(types.uint8, 3, True), _array(types.uint8, 3)
_INDEX = _array(types.intp, 1, True)
_RUNS = (_INDEX,) * 5  # run_start, plane, y, level, shift of a SearchTemplate
#: The one signature each kernel is compiled for.
SIGNATURES = {
    "distance_planes": types.float32(
        _F32_IN, _F32_IN, _SIZES, _SIZES, types.boolean, types.boolean, _F32_OUT
    ),
    "quantize": types.void(_F32_IN, types.float64, _STACK_OUT),
    "search_table": types.void(_STACK_IN, types.intp, types.boolean, _STACK_OUT),
    "coarse_costs": _array(types.int64, 2)(_STACK_IN, types.intp, *_RUNS),
    "table_costs": _array(types.int64, 1)(_STACK_IN, types.intp, *_RUNS, _INDEX, _INDEX),
}


# helpers first: each kernel is compiled where it is defined


@njit(cache=True, nogil=True)
def wrap(j: int, n: int) -> int:
    """``j % n`` for 0 <= j < 2 n, without a division."""
    return j - n if j >= n else j


@njit(cache=True, nogil=True)
def _position(j: int, step: int, blocks: int) -> int:
    """Row of current column j (0 <= j < n) within a (goal residue, plane) block of the table:
    columns j, j + step, j + 2 * step, ... are consecutive rows."""
    return (j % step) * blocks + j // step


@njit(cache=True, nogil=True)
def _fill_by_columns(out: U8Array, plane: U8Array, k: int, n_planes: int, step: int) -> None:
    """Level 0 of :func:`search_table` for scale plane k from ``plane[goal col, current col]``:
    each table row gathers one current column of the plane (a transposition)."""
    n = plane.shape[0]
    blocks = n // step
    for res in range(step):
        first = (res * n_planes + k) * n
        for r in range(step):  # current column j = step * q + r: row first + r * blocks + q
            for q in range(blocks):
                row, j = out[first + r * blocks + q], step * q + r
                for b in range(blocks):
                    row[b] = plane[res + step * b, j]


@njit(cache=True, nogil=True)
def _fill_by_rows(out: U8Array, plane: U8Array, k: int, n_planes: int, step: int) -> None:
    """As :func:`_fill_by_columns` from the transposed plane, ``plane[current col, goal col]``
    (the swapped views' reading): each table row takes every step-th entry of one plane row,
    which LLVM vectorises."""
    n = plane.shape[0]
    blocks = n // step
    for res in range(step):
        first = (res * n_planes + k) * n
        for r in range(step):
            for q in range(blocks):
                row, source = out[first + r * blocks + q], plane[step * q + r]
                for b in range(blocks):
                    row[b] = source[res + step * b]


@njit(cache=True, nogil=True)
def _fold(best: U8Array, one: U8Array, two: U8Array, first: bool) -> None:
    """``best = minimum(one, two)`` if ``first``, else ``minimum(best, one, two)``, in place, in
    one pass (ternaries, not min(): LLVM vectorises them). A one-window run passes its row
    twice."""
    if first:
        for a in range(best.size):
            low, high = one[a], two[a]
            best[a] = low if low < high else high
    else:
        for a in range(best.size):
            low, high, kept = one[a], two[a], best[a]
            value = low if low < high else high
            best[a] = value if value < kept else kept


@njit(cache=True, nogil=True)
def _add(total: NDArray[np.int32], part: U8Array) -> None:
    """``total += part`` in place."""
    for a in range(part.size):
        total[a] += part[a]


@njit(SIGNATURES["distance_planes"], cache=True, nogil=True)
def distance_planes(
    goal: NDArray[np.float32],
    current: NDArray[np.float32],
    size_goal: NDArray[np.float32],
    size_current: NDArray[np.float32],
    squared: bool,
    normalized: bool,
    out: NDArray[np.float32],
) -> float:
    """Fill ``out`` (n_scales, n, n) [plane, goal col, current col] with one column distance;
    return its largest entry.

    ``goal``, ``current``: magnified bands (h + 1, rows, n), plane m >= 0 pairs goal plane m with
    current plane 0, m < 0 goal plane 0 with current plane -m; ``size_*`` (h + 1, n): each
    column's sum of squares (``squared``) or of magnitudes, the normaliser when ``normalized``.
    """
    h = goal.shape[0] - 1
    rows, n = goal.shape[1], goal.shape[2]
    acc = np.empty(n, dtype=np.float32)
    peak = np.zeros(n, dtype=np.float32)  # per current column: distances are >= 0
    for m in range(-h, h + 1):
        kg, kc = (m, 0) if m >= 0 else (0, -m)
        for i in range(n):
            for j in range(n):
                acc[j] = 0.0
            for r in range(rows):
                g = goal[kg, r, i]
                row = current[kc, r]
                for j in range(n):
                    d = g - row[j]
                    acc[j] += d * d if squared else abs(d)
            target = out[m + h, i]
            for j in range(n):
                value = acc[j]
                if normalized:
                    total = size_goal[kg, i] + size_current[kc, j]
                    value = value / total if total > 0 else np.float32(0.0)
                target[j] = value
                top = peak[j]  # a ternary, not max(): LLVM vectorises this one
                peak[j] = value if value > top else top
    top = np.float32(0.0)  # a loop, not peak.max(): cheaper to compile
    for j in range(n):
        top = peak[j] if peak[j] > top else top
    return top


@njit(SIGNATURES["quantize"], cache=True, nogil=True)
def quantize(planes: NDArray[np.float32], top: float, out: U8Array) -> None:
    """Write ``planes`` scaled so that ``top``, its largest entry, becomes STACK_MAX, rounded,
    into ``out`` (same shape, uint8)."""
    scale = STACK_MAX / top if top > 0 else 0.0
    for k in range(planes.shape[0]):
        for i in range(planes.shape[1]):
            source, target = planes[k, i], out[k, i]
            for j in range(source.size):
                target[j] = np.uint8(np.rint(source[j] * scale))


@njit(SIGNATURES["search_table"], cache=True, nogil=True)
def search_table(stack: U8Array, step: int, swap: bool, out: U8Array) -> None:
    """Lay the stack out for :func:`coarse_costs` in ``out`` (levels, step * n_scales * n,
    n // step).

    Level 0, row ``(g % step * n_scales + k) * n + position(j)``, entry ``g // step`` holds
    ``D[k, g, j]`` (goal column g, current column j): the goal columns of consecutive alpha
    steps lie side by side, and the current columns of consecutive steps are consecutive rows
    (:func:`_position`). Level v holds the minimum over the current columns ``j .. j + 2**v -
    1`` (circular), so the minimum over any run of L consecutive columns is that of two
    level-floor(log2 L) rows. ``swap``: the stack of the swapped views, ``D'[k, i, j] =
    D[n_scales - 1 - k, j, i]`` (Möller's double search).
    """
    n_planes, n = stack.shape[0], stack.shape[1]
    blocks = n // step
    for k in range(n_planes):
        if swap:
            _fill_by_rows(out[0], stack[n_planes - 1 - k], k, n_planes, step)
        else:
            _fill_by_columns(out[0], stack[k], k, n_planes, step)
    flat = out.reshape(out.shape[0], -1)
    for v in range(1, out.shape[0]):
        half, below, level = 1 << (v - 1), flat[v - 1], flat[v]
        # current columns j = step * q + r, r fixed, are consecutive rows; so are the columns
        # j + half of their windows' other halves, up to the wrap past column n - 1
        for first in range(0, out.shape[1], n):
            for r in range(step):
                row = (first + r * blocks) * blocks
                other = (first + (r + half) % step * blocks) * blocks
                carry = (r + half) // step * blocks  # rows before the wrap: blocks - carry
                size = blocks * blocks - carry
                _fold(level[row : row + size], below[row : row + size],
                      below[other + carry : other + carry + size], True)  # fmt: skip
                row += size
                _fold(level[row : row + carry], below[row : row + carry],
                      below[other : other + carry], True)  # fmt: skip


@njit(SIGNATURES["coarse_costs"], cache=True, nogil=True)
def coarse_costs(
    table: U8Array,
    step: int,
    run_start: IntArray,
    plane: IntArray,
    y: IntArray,
    level: IntArray,
    shift: IntArray,
) -> NDArray[np.int64]:
    """Min-warping cost of every (alpha, psi) step: (n_steps, n_steps), [alpha, psi].

    ``table``: :func:`search_table`; goal offset x's admissible pairs are the runs q in
    ``run_start[x] .. run_start[x + 1] - 1`` of current offsets ``y[q] ..`` on plane
    ``plane[q]``, whose minimum is that of the level ``level[q]`` rows at ``y[q]`` and ``y[q] +
    shift[q]``. Goal column first: the running minima of x (n_steps x n_steps 8-bit entries,
    [s, goal block]) stay in the first-level cache while each run folds in the table rows of
    consecutive s = alpha - psi, which are consecutive rows: a few long contiguous passes per
    run (the first run of x writes the minima, the others fold into them). The minima are added
    to the costs once per x, at alpha = goal block - x // step (a doubled cost row takes the
    wrap). The goal offsets of one residue modulo ``step`` come one after another: they read
    the same table blocks.
    """
    blocks = table.shape[2]
    n = blocks * step
    n_planes = table.shape[1] // n // step
    cost = np.zeros((blocks, 2 * blocks), dtype=np.int32)  # [s, alpha + blocks or alpha]
    best = np.empty((blocks, blocks), dtype=np.uint8)  # [s, goal block]
    flat_best = best.reshape(-1)
    for index in range(n):  # goal offsets of one residue first: they read the same table rows
        x = index % blocks * step + index // blocks
        first, last = run_start[x], run_start[x + 1]
        if first == last:
            continue
        res, base = x % step, x // step
        for q in range(first, last):
            rows, rank = table[level[q]].reshape(-1), (res * n_planes + plane[q]) * n
            y2 = (y[q] + shift[q]) % n
            # each window: its block's first table row, and its row at s = 0 within the block
            near, near_start = rank + (y[q] % step) * blocks, y[q] // step
            far, far_start = rank + (y2 % step) * blocks, y2 // step
            # the s at which a window's rows wrap round to the first row of its block
            wrap_near, wrap_far = blocks - near_start, blocks - far_start
            low, high = min(wrap_near, wrap_far), max(wrap_near, wrap_far)
            for s0, s1 in ((0, low), (low, high), (high, blocks)):
                if s0 < s1:
                    one = (near + wrap(near_start + s0, blocks)) * blocks
                    other = (far + wrap(far_start + s0, blocks)) * blocks
                    size, at = (s1 - s0) * blocks, s0 * blocks
                    _fold(flat_best[at : at + size], rows[one : one + size],
                          rows[other : other + size], q == first)  # fmt: skip
        for s in range(blocks):  # goal block b is alpha (b - base) % blocks
            _add(cost[s, blocks - base : 2 * blocks - base], best[s])
    out = np.empty((blocks, blocks), dtype=np.int64)
    for s in range(blocks):
        for a in range(blocks):
            out[a, wrap(a - s + blocks, blocks)] = cost[s, a] + cost[s, a + blocks]
    return out


@njit(SIGNATURES["table_costs"], cache=True, nogil=True)
def table_costs(
    table: U8Array,
    step: int,
    run_start: IntArray,
    plane: IntArray,
    y: IntArray,
    level: IntArray,
    shift: IntArray,
    alphas: IntArray,
    psis: IntArray,
) -> NDArray[np.int64]:
    """Min-warping costs (m,) of the (alpha, psi) pairs ``alphas``, ``psis`` (m,) in band
    columns, read from :func:`search_table` (the other arguments as :func:`coarse_costs`)."""
    blocks = table.shape[2]
    n = blocks * step
    n_planes = table.shape[1] // n // step
    position, rank, block = np.empty(n, np.intp), np.empty(n, np.intp), np.empty(n, np.intp)
    for j in range(n):  # look-up tables: no integer division in the loops below
        position[j] = _position(j, step, blocks)
        rank[j], block[j] = j % step * n_planes * n, j // step
    m = alphas.size
    alpha, turn = np.empty(m, dtype=np.intp), np.empty(m, dtype=np.intp)
    for pair in range(m):
        alpha[pair], turn[pair] = alphas[pair] % n, (alphas[pair] - psis[pair]) % n
    out = np.zeros(m, dtype=np.int64)
    low = np.empty(m, dtype=np.intp)
    for x in range(n):  # goal column first: nearby pairs read nearby table entries
        first, last = run_start[x], run_start[x + 1]
        if first == last:
            continue
        for pair in range(m):
            low[pair] = STACK_MAX
        for q in range(first, last):
            rows, shifted, offset = table[level[q]], shift[q], plane[q] * n
            for pair in range(m):
                i = wrap(x + alpha[pair], n)
                j = wrap(y[q] + turn[pair], n)
                row, b = rank[i] + offset, block[i]
                near = rows[row + position[j], b]
                far = rows[row + position[wrap(j + shifted, n)], b]
                near = near if near < far else far
                low[pair] = near if near < low[pair] else low[pair]
        for pair in range(m):
            out[pair] += low[pair]
    return out
