"""Min-warping's second phase: the admissible pairs, the searches and the buffers they reuse.

:func:`search_template` traces which (scale plane, current column) pairs some ``rho >= 0`` gives
each goal column; :func:`reference_costs` is the pure-numpy search (every pair looked up), which
the compiled search (:class:`CompiledSearch`, :mod:`homebench.methods.min_warping.kernels`)
is tested against: both return the same integers.

**Buffers.** A compiled search lays the 8-bit stack out in two tables of windowed minima (4.5 MB
each at 288 columns) and the stack comes from a float stack of 3 MB: allocated afresh for every
pair, such arrays cost page faults in a process whose allocator hands large blocks back to the
kernel at once (glibc's default: 4,300 faults and 8 ms of system time per pair in a plain
Python process). :func:`workspace` gives each thread its own :class:`Workspace`, whose arrays
are kept from one call to the next (about 13 MB per thread that searched). Threads never share
one; a forked child gets a copy of its parent's; every kernel overwrites whatever it later
reads, so results never depend on a buffer's history.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from types import ModuleType
from typing import Any, Protocol

import numpy as np
from numpy.lib.stride_tricks import as_strided
from numpy.typing import DTypeLike, NDArray

from homebench.geometry import TWO_PI

IntArray = NDArray[np.intp]
I64Array = NDArray[np.int64]
U8Array = NDArray[np.uint8]

#: rho samples per band column (over rho in [0, 1 + max_scale]) when tracing admissible pairs.
_RHO_SAMPLES_PER_COLUMN = 40
#: Goal columns traced at a time by :func:`search_template` (its arrays then stay in cache).
_TEMPLATE_BLOCK = 8


@dataclass(frozen=True)
class SearchTemplate:
    """Admissible (scale plane, current offset) pairs of every goal offset x, x-major.

    Goal offset x (columns from alpha, 0 .. n - 1) may be seen at current offset ``y[e]``
    (columns from alpha) on plane ``plane[e]`` (0 .. n_scales - 1, sigma increasing) for e in
    ``x_start[x] .. x_start[x + 1] - 1``; shapes (n + 1,), (E,), (E,). The same pairs as runs
    of consecutive current offsets on one plane (circular), for the compiled search: run q of x
    (``run_start[x] <= q < run_start[x + 1]``) covers ``run_length[q]`` offsets from
    ``run_y[q]`` on ``run_plane[q]``; ``run_level[q] = floor(log2 run_length[q])`` and
    ``run_shift[q] = run_length[q] - 2**run_level[q]`` (two overlapping power-of-two windows).
    Every array is contiguous, (R,) for the runs.
    """

    x_start: IntArray
    plane: IntArray
    y: IntArray
    run_start: IntArray
    run_plane: IntArray
    run_y: IntArray
    run_length: IntArray
    run_level: IntArray
    run_shift: IntArray

    @property
    def runs(self) -> tuple[IntArray, IntArray, IntArray, IntArray, IntArray]:
        """The runs as the compiled search takes them: start, plane, y, level, shift."""
        return self.run_start, self.run_plane, self.run_y, self.run_level, self.run_shift


@lru_cache(maxsize=8)
def search_template(n_columns: int, n_scales: int, max_scale: float) -> SearchTemplate:
    """Trace every goal column's admissible pairs over rho >= 0 (see the module docstring of
    :mod:`homebench.methods.min_warping.method`)."""
    # keys grow with the goal column: each block's sorted keys follow the block before's
    blocks = range(0, n_columns, _TEMPLATE_BLOCK)
    keys = np.concatenate(
        [_template_keys(range(b, min(b + _TEMPLATE_BLOCK, n_columns)), n_columns, n_scales,
                        max_scale) for b in blocks]
    )  # fmt: skip
    x_of, plane, y_of = (
        keys // (n_scales * n_columns),
        keys // n_columns % n_scales,
        keys % n_columns,
    )
    counts = np.bincount(x_of, minlength=n_columns)
    starts = _starts(counts.tolist())
    pairs = np.stack([plane, y_of], axis=1)
    per_x = [pairs[starts[i] : starts[i + 1]] for i in range(n_columns)]
    runs = [_runs(pairs, n_columns) for pairs in per_x]
    table = [run for x_runs in runs for run in x_runs]
    run_plane, run_y, run_length = (np.array(c, dtype=np.intp) for c in zip(*table, strict=True))
    run_level = np.floor(np.log2(run_length)).astype(np.intp)
    return SearchTemplate(
        starts,
        plane,
        y_of,
        _starts([len(x_runs) for x_runs in runs]),
        run_plane,
        run_y,
        run_length,
        run_level,
        run_length - (1 << run_level),
    )


def _template_keys(columns: range, n_columns: int, n_scales: int, max_scale: float) -> IntArray:
    """Sorted unique keys ``(x * n_scales + plane) * n_columns + y`` of the admissible pairs of
    goal columns ``columns``, traced over rho (the elementwise maths of one block of the
    (n_columns, samples) grid, so the blocks' arrays stay in cache)."""
    h = (n_scales - 1) // 2
    rho = np.linspace(0.0, 1.0 + max_scale, _RHO_SAMPLES_PER_COLUMN * n_columns + 1)[None, :]
    x = (TWO_PI / n_columns) * np.arange(n_columns)[columns.start : columns.stop, None]
    distance2 = 1.0 - 2.0 * rho * np.cos(x) + rho**2  # (len(columns), samples)
    row, sample = np.nonzero(distance2 > 1e-12)
    distance2 = distance2[row, sample]
    y = np.arctan2(np.sin(x[row, 0]), np.cos(x[row, 0]) - rho[0, sample])
    m = np.rint(-0.5 * h * np.log(distance2) / np.log(max_scale)).astype(np.intp)
    inside = np.abs(m) <= h
    y_col = np.rint(y[inside] * (n_columns / TWO_PI)).astype(np.intp) % n_columns
    x_col = row[inside] + columns.start
    return np.unique((x_col * n_scales + m[inside] + h) * n_columns + y_col)


def _starts(counts: list[int]) -> IntArray:
    """Offsets (len(counts) + 1,) of consecutive groups of the given sizes."""
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)


def _runs(pairs: IntArray, n_columns: int) -> list[tuple[int, int, int]]:
    """Group sorted unique (plane, column) pairs into circular runs (plane, start, length)."""
    runs: list[tuple[int, int, int]] = []
    for plane in np.unique(pairs[:, 0]):
        cols = pairs[pairs[:, 0] == plane, 1]
        groups = [list(g) for g in np.split(cols, np.flatnonzero(np.diff(cols) != 1) + 1)]
        if len(groups) > 1 and groups[0][0] == 0 and groups[-1][-1] == n_columns - 1:
            groups[0] = groups.pop() + groups[0]  # the run wraps past the last column
        runs.extend((int(plane), int(g[0]), len(g)) for g in groups)
    return runs


def reference_costs(
    stack: NDArray[np.generic], template: SearchTemplate, alphas: IntArray, psis: IntArray
) -> NDArray[np.generic]:
    """Pure-numpy search: cost (len(alphas), len(psis)) of (alpha, psi) in columns on ``stack``
    (n_scales, n, n) [plane, goal col, current col]; every admissible pair looked up. Integer
    stacks sum in int64."""
    n = stack.shape[1]
    rows = np.repeat(np.arange(n), np.diff(template.x_start))  # goal offset of each pair
    firsts = template.x_start[:-1][np.diff(template.x_start) > 0]
    kind = np.int64 if np.issubdtype(stack.dtype, np.integer) else np.float64
    cost = np.empty((len(alphas), len(psis)), dtype=kind)
    for row, alpha in enumerate(alphas):
        current = (template.y[:, None] + alpha - np.asarray(psis)[None, :]) % n
        values = stack[template.plane[:, None], (rows[:, None] + alpha) % n, current]
        cost[row] = np.minimum.reduceat(values, firsts, axis=0).sum(axis=0, dtype=kind)
    return cost


def rotation_costs(plane: NDArray[np.integer], psis: IntArray) -> I64Array:
    """Cost (m,) of the pure rotations by ``psis`` (m,) in band columns on the unit plane
    (n, n) [goal col, current col]: ``sum over i of plane[i, (i - psi) % n]``, int64.

    Every rotation's cost is a wrapped diagonal sum: with the plane twice side by side, row i
    from column i on holds ``plane[i, (i + k) % n]`` at k, so a strided view (row step: one row
    and one column) lines the diagonals up as columns, summed in one pass.
    """
    n = plane.shape[0]
    twice = np.concatenate([plane, plane], axis=1)
    rows, columns = twice.strides
    diagonals = as_strided(twice, shape=(n, n), strides=(rows + columns, columns), writeable=False)
    return diagonals.sum(axis=0, dtype=np.int64)[(-np.asarray(psis)) % n]


def swapped(stack: NDArray[np.generic]) -> NDArray[np.generic]:
    """The stack of the swapped views (goal <-> current): ``D'[k, i, j] = D[K - 1 - k, j, i]``."""
    return stack[::-1].transpose(0, 2, 1)


class Workspace:
    """Arrays kept by one thread for its next min-warping calls, by name (see the module
    docstring). An array is made anew only when a call asks for another shape or type; each
    remembers who asked for it last (an ``owner``: a number from :func:`new_owner`, never
    reused), so that a search can tell whether a table still holds what it wrote."""

    def __init__(self) -> None:
        self._arrays: dict[str, tuple[np.ndarray, int]] = {}

    def array(
        self, name: str, shape: tuple[int, ...], dtype: DTypeLike, owner: int
    ) -> tuple[np.ndarray, bool]:
        """The array kept as ``name``, of ``shape`` and ``dtype``, and whether ``owner`` asked
        for it last (its content is then what ``owner`` wrote, otherwise undefined)."""
        kept, last = self._arrays.get(name, (None, -1))
        if kept is None or kept.shape != shape or kept.dtype != dtype:
            kept, last = np.empty(shape, dtype), -1
        self._arrays[name] = kept, owner
        return kept, last == owner


_OWNERS = itertools.count()


def new_owner() -> int:
    """A number no other user of a :class:`Workspace` gets."""
    return next(_OWNERS)


_LOCAL = threading.local()


def workspace() -> Workspace:
    """This thread's :class:`Workspace`."""
    if not hasattr(_LOCAL, "workspace"):
        _LOCAL.workspace = Workspace()
    return _LOCAL.workspace


def kernels() -> ModuleType:
    """The compiled kernels, imported by their first use: importing min-warping (as the
    command line does for every method) does not import numba."""
    from homebench.methods.min_warping import kernels

    return kernels


class CostSearch(Protocol):
    """Costs of (alpha, psi) hypotheses on one pair's stack, of both readings (``swap``: the
    swapped views'): what min-warping's double and fine search ask of a search."""

    def coarse(self, swap: bool) -> I64Array:
        """Cost of every (alpha, psi) step: (n_steps, n_steps), [alpha step, psi step]."""
        ...

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        """Costs (m,) of (alpha, psi) pairs (m,) in band columns."""
        ...


#: A pure-numpy search: ``costs(stack, template, alphas, psis)``, (len(alphas), len(psis)).
ReferenceCosts = Callable[[U8Array, Any, IntArray, IntArray], I64Array]


class NumpySearch:
    """Costs by a pure-numpy reading (``costs``; min-warping's :func:`reference_costs` by
    default) with its ``template`` on a stack (K, n, n)."""

    def __init__(
        self, stack: U8Array, template: Any, step: int, costs: ReferenceCosts = reference_costs
    ) -> None:
        self.stack, self.template, self.step, self.costs = stack, template, step, costs

    def coarse(self, swap: bool) -> I64Array:
        """Cost of every (alpha, psi) step: (n_steps, n_steps), [alpha step, psi step]."""
        grid = self.step * np.arange(self.stack.shape[1] // self.step)
        return self.costs(self._source(swap), self.template, grid, grid)

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        """Costs (m,) of (alpha, psi) pairs (m,) in band columns."""
        n, source = self.stack.shape[1], self._source(swap)
        pairs = zip(alphas % n, psis % n, strict=True)
        return np.array([self.costs(source, self.template, [a], [p])[0, 0] for a, p in pairs])

    def _source(self, swap: bool) -> U8Array:
        return swapped(self.stack) if swap else self.stack


class CompiledSearch:
    """Costs by the numba kernels, as :class:`NumpySearch`; each reading's table of windowed
    minima is built once, into this thread's :class:`Workspace`."""

    def __init__(self, stack: U8Array, template: SearchTemplate, step: int) -> None:
        self.kernels, self.workspace, self.owner = kernels(), workspace(), new_owner()
        self.stack, self.step, self.n, self.runs = stack, step, stack.shape[1], template.runs
        levels = int(template.run_level.max()) + 1
        self.shape = (levels, step * stack.shape[0] * self.n, self.n // step)

    def coarse(self, swap: bool) -> I64Array:
        """As :meth:`NumpySearch.coarse`."""
        return self.kernels.coarse_costs(self._table(swap), self.step, *self.runs)

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        """As :meth:`NumpySearch.at`."""
        indices = (np.ascontiguousarray(v, dtype=np.intp) for v in (alphas, psis))
        return self.kernels.table_costs(self._table(swap), self.step, *self.runs, *indices)

    def _table(self, swap: bool) -> U8Array:
        table, built = self.workspace.array(f"table {swap}", self.shape, np.uint8, self.owner)
        if not built:
            self.kernels.search_table(self.stack, self.step, swap, table)
        return table
