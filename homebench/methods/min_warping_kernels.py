"""Compiled (numba) kernels of min-warping: the 16-bit column-distance stack and the searches.

The pure-numpy reading in :mod:`homebench.methods.min_warping` is the reference; these kernels
return the same integers (the search) or the same stack up to one unit of the 16-bit scale (the
distances: float32 sums in a fixed order against numpy's float64). Why numba: the search takes
the minimum of about 10**8 small integers (288 goal columns x 96 x 96 steps x about 50
admissible pairs); numpy needs index arrays as large as that (or a Python loop over alphas), a
compiled loop over contiguous 16-bit rows does it in SIMD registers, as Möller's C++ does.
Beyond his code, the pairs of one goal column are runs of consecutive current columns on one
plane (2,095 runs for 14,923 pairs at 288 columns), and a table of minima over power-of-two
windows of current columns answers a run with two look-ups.

Determinism: no ``fastmath`` (no reassociation, no fused multiply-add), no ``parallel``; float
sums run elementwise over the current columns, each in a fixed order over the rows, so vector
width does not change a result; the search is integer. ``nogil`` lets threads share a process.
``cache=True`` keeps the machine code in this package's ``__pycache__`` (numba writes it
atomically; without write access it falls back to a user cache directory).

:mod:`~homebench.methods.min_warping` imports this module at its first compiled search, not
with itself, so that a process that only lists or checks methods does not import numba (a
third of a second of CPU); a job worker server imports it before forking the workers of a run
with min-warping (the method's ``preload_modules``).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from homebench.methods.min_warping import STACK_MAX


@njit(cache=True, nogil=True)
def distance_planes(
    goal: NDArray[np.float32],
    current: NDArray[np.float32],
    size_goal: NDArray[np.float32],
    size_current: NDArray[np.float32],
    squared: bool,
    normalized: bool,
) -> NDArray[np.float32]:
    """Float stack (n_scales, n, n) [plane, goal col, current col] of one column distance.

    ``goal``, ``current``: magnified bands (h + 1, rows, n), plane m >= 0 pairs goal plane m with
    current plane 0, m < 0 goal plane 0 with current plane -m; ``size_*`` (h + 1, n): each
    column's sum of squares (``squared``) or of magnitudes, the normaliser when ``normalized``.
    """
    h = goal.shape[0] - 1
    rows, n = goal.shape[1], goal.shape[2]
    out = np.empty((2 * h + 1, n, n), dtype=np.float32)
    acc = np.empty(n, dtype=np.float32)
    for m in range(-h, h + 1):
        kg, kc = (m, 0) if m >= 0 else (0, -m)
        for i in range(n):
            acc[:] = 0.0
            for r in range(rows):
                g = goal[kg, r, i]
                row = current[kc, r]
                for j in range(n):
                    d = g - row[j]
                    acc[j] += d * d if squared else abs(d)
            for j in range(n):
                value = acc[j]
                if normalized:
                    total = size_goal[kg, i] + size_current[kc, j]
                    value = value / total if total > 0 else np.float32(0.0)
                out[m + h, i, j] = value
    return out


@njit(cache=True, nogil=True)
def quantize(stack: NDArray[np.float32], top: float) -> NDArray[np.uint16]:
    """``stack`` scaled so that ``top``, its largest entry, becomes STACK_MAX, rounded to uint16
    (same shape). The caller finds ``top`` (numpy's max is vectorised; a compiled float max
    is not, without fastmath)."""
    scale = STACK_MAX / top if top > 0 else 0.0
    out = np.empty(stack.shape, dtype=np.uint16)
    flat, flat_out = stack.ravel(), out.ravel()
    for e in range(flat.size):
        flat_out[e] = np.uint16(np.rint(flat[e] * scale))
    return out


@njit(cache=True, nogil=True)
def search_table(
    stack: NDArray[np.uint16], step: int, swap: bool, levels: int
) -> NDArray[np.uint16]:
    """The stack laid out for :func:`coarse_costs`: (levels, step * n_scales * n, n // step).

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
    position = np.empty(n, dtype=np.intp)
    for j in range(n):
        position[j] = _position(j, step, blocks)
    out = np.empty((levels, step * n_planes * n, blocks), dtype=np.uint16)
    for k in range(n_planes):
        if swap:
            _fill(out[0], stack[n_planes - 1 - k].T, k, n_planes, step, position)
        else:
            _fill(out[0], stack[k], k, n_planes, step, position)
    for v in range(1, levels):
        half, below, level = 1 << (v - 1), out[v - 1], out[v]
        for first in range(0, out.shape[1], n):
            for j in range(n):
                row, other = first + position[j], first + position[(j + half) % n]
                for a in range(blocks):  # a ternary, not min(): LLVM vectorises this one
                    low, high = below[row, a], below[other, a]
                    level[row, a] = low if low < high else high
    return out


@njit(cache=True, nogil=True)
def _fill(
    out: NDArray[np.uint16],
    plane: NDArray[np.uint16],
    k: int,
    n_planes: int,
    step: int,
    position: NDArray[np.intp],
) -> None:
    """Level 0 of :func:`search_table` for scale plane k from ``plane[goal col, current col]``."""
    n = plane.shape[0]
    blocks = n // step
    for res in range(step):
        first = (res * n_planes + k) * n
        for j in range(n):
            row = out[first + position[j]]
            for b in range(blocks):
                row[b] = plane[res + step * b, j]


@njit(cache=True, nogil=True, inline="always")
def _position(j: int, step: int, blocks: int) -> int:
    """Row of current column j (0 <= j < n) within a (goal residue, plane) block of the table:
    columns j, j + step, j + 2 * step, ... are consecutive rows."""
    return (j % step) * blocks + j // step


@njit(cache=True, nogil=True)
def coarse_costs(
    table: NDArray[np.uint16],
    step: int,
    run_start: NDArray[np.intp],
    plane: NDArray[np.intp],
    y: NDArray[np.intp],
    level: NDArray[np.intp],
    shift: NDArray[np.intp],
) -> NDArray[np.int64]:
    """Min-warping cost of every (alpha, s) step: (n_steps, n_steps), s = alpha - psi.

    ``table``: :func:`search_table`; goal offset x's admissible pairs are the runs q in
    ``run_start[x] .. run_start[x + 1] - 1`` of current offsets ``y[q] ..`` on plane
    ``plane[q]``, whose minimum is that of the level ``level[q]`` rows at ``y[q]`` and ``y[q] +
    shift[q]``. Goal column first: the running minima of x (n_steps x n_steps 16-bit entries,
    [s, goal block]) stay in the first-level cache while each run folds in the table rows of
    consecutive s, which are consecutive rows: a few long contiguous passes per run. The minima
    are added to the costs once per x, at alpha = goal block - x // step (a doubled cost row
    takes the wrap).
    """
    blocks = table.shape[2]
    n = blocks * step
    n_planes = table.shape[1] // n // step
    cost = np.zeros((blocks, 2 * blocks), dtype=np.int32)  # [s, alpha + blocks or alpha]
    best = np.empty((blocks, blocks), dtype=np.uint16)  # [s, goal block]
    flat_best = best.reshape(-1)
    for x in range(n):
        first, last = run_start[x], run_start[x + 1]
        if first == last:
            continue
        res, base = x % step, x // step
        flat_best[:] = 65535
        for q in range(first, last):
            rows, rank = table[level[q]].reshape(-1), (res * n_planes + plane[q]) * n
            y2 = (y[q] + shift[q]) % n
            # each window: its block's first table row, and its row at s = 0 within the block
            near, near_start = rank + (y[q] % step) * blocks, y[q] // step
            far, far_start = rank + (y2 % step) * blocks, y2 // step
            two = shift[q] != 0
            # the s at which a window's rows wrap round to the first row of its block
            wrap_near, wrap_far = blocks - near_start, blocks - far_start if two else blocks
            low, high = min(wrap_near, wrap_far), max(wrap_near, wrap_far)
            for s0, s1 in ((0, low), (low, high), (high, blocks)):
                if s0 < s1:
                    one = (near + _wrap(near_start + s0, blocks)) * blocks
                    other = (far + _wrap(far_start + s0, blocks)) * blocks
                    _fold_rows(flat_best, rows, s0 * blocks, one, other if two else -1,
                               (s1 - s0) * blocks)  # fmt: skip
        for s in range(blocks):  # goal block b is alpha (b - base) % blocks
            _add(cost[s, blocks - base : 2 * blocks - base], best[s])
    out = np.empty((blocks, blocks), dtype=np.int64)
    for s in range(blocks):
        for a in range(blocks):
            out[s, a] = cost[s, a] + cost[s, a + blocks]
    return out


@njit(cache=True, nogil=True, inline="always")
def _fold_rows(
    flat_best: NDArray[np.uint16], rows: NDArray[np.uint16], out: int, one: int, other: int,
    size: int,
) -> None:  # fmt: skip
    """Fold the ``size`` table entries from flat offset ``one`` of ``rows`` (their minimum with
    those from ``other``, unless it is -1) into the minima ``flat_best`` from offset ``out``."""
    if other < 0:
        _fold_min(flat_best[out : out + size], rows[one : one + size])
    else:
        _fold_min2(flat_best[out : out + size], rows[one : one + size], rows[other : other + size])


@njit(cache=True, nogil=True, inline="always")
def _fold_min(best: NDArray[np.uint16], row: NDArray[np.uint16]) -> None:
    """``best = minimum(best, row)`` in place (a ternary, not min(): LLVM vectorises it)."""
    for a in range(best.size):
        value, low = row[a], best[a]
        best[a] = value if value < low else low


@njit(cache=True, nogil=True, inline="always")
def _fold_min2(best: NDArray[np.uint16], one: NDArray[np.uint16], two: NDArray[np.uint16]) -> None:
    """``best = minimum(best, one, two)`` in place, in one pass over ``best``."""
    for a in range(best.size):
        first, second, low = one[a], two[a], best[a]
        value = first if first < second else second
        best[a] = value if value < low else low


@njit(cache=True, nogil=True, inline="always")
def _add(total: NDArray[np.int32], part: NDArray[np.uint16]) -> None:
    """``total += part`` in place."""
    for a in range(part.size):
        total[a] += part[a]


@njit(cache=True, nogil=True)
def table_costs(
    table: NDArray[np.uint16],
    step: int,
    run_start: NDArray[np.intp],
    plane: NDArray[np.intp],
    y: NDArray[np.intp],
    level: NDArray[np.intp],
    shift: NDArray[np.intp],
    alphas: NDArray[np.intp],
    psis: NDArray[np.intp],
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
    low = np.empty(m, dtype=np.int64)
    for x in range(n):  # goal column first: nearby pairs read nearby table entries
        first, last = run_start[x], run_start[x + 1]
        if first == last:
            continue
        low[:] = 65535
        for q in range(first, last):
            rows, shifted, offset = table[level[q]], shift[q], plane[q] * n
            for pair in range(m):
                i = _wrap(x + alpha[pair], n)
                j = _wrap(y[q] + turn[pair], n)
                row, b = rank[i] + offset, block[i]
                near = rows[row + position[j], b]
                far = rows[row + position[_wrap(j + shifted, n)], b]
                low[pair] = min(low[pair], near, far)
        out += low
    return out


@njit(cache=True, nogil=True, inline="always")
def _wrap(j: int, n: int) -> int:
    """``j % n`` for 0 <= j < 2 n, without a division."""
    return j - n if j >= n else j
