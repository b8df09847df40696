"""Möller's min-warping (Möller 2009; Möller, Krzykawski, Gerstmayr 2010) on the horizon band.

Same movement model as 1-D warping (see :mod:`homebench.methods.warping`): the robot left the
goal in direction ``alpha`` and turned by ``psi``; but the equal-distance assumption is dropped.
Each goal column (a landmark at angle ``x = theta - alpha`` from the movement direction) may have
its own relative distance ``rho = d / r``; from the current place it appears at
``y = atan2(sin x, cos x - rho)`` (also relative to alpha; current azimuth ``y + alpha - psi``),
and its vertical size changes by ``sigma = r / r' = 1 / sqrt(1 - 2 rho cos x + rho**2)``.

Implementation (the paper's two phases):

1. **Scale-plane stack** ``D[k, i, j]``: distance between goal column i and current column j,
   with the goal column magnified vertically (about the horizon) by ``sigma_k >= 1``, or the
   current column by ``1 / sigma_k`` when ``sigma_k < 1``, so only magnification (sampling
   inside the band) is ever needed. ``sigma_k = max_scale**(m / h)`` for ``m = -h .. h``
   (``n_scales = 2h + 1`` planes); magnified band images are made in ``describe``, once per
   image. The column distance (``distance``) and the vertical edge filter before it
   (``edge_filter``) are Möller's (see below).
2. **Search**: for every (alpha, psi) step (``n_columns`` steps a turn, ``columns_per_step``
   band columns each) and every goal column of the band, the minimum of D over the (current
   column, scale plane) pairs that some ``rho >= 0`` produces (current column and scale
   quantised to the nearest column / plane; scales beyond ``max_scale`` are not searched),
   summed over the goal columns; the best (alpha, psi) wins and ``beta = alpha - psi + pi``.
3. **Double search** (Möller's, ``double_search``): the same search on the stack of the swapped
   views (goal <-> current: ``D'[k, i, j] = D[n_scales - 1 - k, j, i]``), whose parameters
   ``(alpha', psi') = (alpha - psi + pi, -psi)`` describe the same movement; the two costs are
   added at corresponding parameters before the best is taken.
4. **Fine search** (Möller's, ``fine_search``): every (alpha, psi) within ``columns_per_step -
   1`` band columns of the best step is evaluated at full band resolution (both views with the
   double search); the lowest cost wins (ties: the first in psi-major, alpha-minor order).

**Integers.** As in Möller's SIMD code the stack is kept in 16 bits: each pair's float stack
is scaled so its largest entry is 65535 and rounded (``quantize``; a relative step of 1.5e-5 of
the pair's largest distance), costs are exact integer sums (int64), so ties and the optimum
do not depend on summation order. The search runs in compiled kernels
(:mod:`homebench.methods.min_warping_kernels`, numba: goal column first, the running minima of
all alphas of one (goal column, psi) in one vector; each run of consecutive admissible current
columns on one plane answered by two look-ups in a table of windowed minima);
:func:`reference_costs` and :meth:`MinWarping.distance_stack` are the pure-numpy reading they
are tested against (``home(..., engine="numpy")`` gives the same estimate).

**Column distances.** For columns a, b (vectors over the band's rows): ``ssd`` = sum (a - b)**2,
``sad`` = sum |a - b|; a leading ``z`` subtracts each column's mean first (the distance is then
unchanged by adding a constant to a column); a leading ``n`` divides by the columns' summed
magnitudes, ``nssd`` = sum (a - b)**2 / sum (a**2 + b**2) in [0, 2] and ``nsad`` = sum |a - b|
/ sum (|a| + |b|) in [0, 1] (unchanged when both columns are scaled alike; two zero columns
match at 0). ``nsad`` is Möller's normalised sum of absolute differences as his SIMD
implementation computes it (Möller 2016-2018, the ``firstPhaseNSAD2`` default of
``warpingSIMDTest``: the joint term over the sum of the two columns' absolute sums), on images
through a vertical edge filter (the difference of vertically adjacent pixels), which removes
any offset; edges are computed before magnification, as there. Möller et al. (2014, "Illumination
tolerance for visual navigation with the holistic min-warping method") compare such measures;
the others here are the plain, zero-mean and normalised variants of the two sums.

No direction without evidence (a reading): every (alpha, psi) can explain a pure rotation (y = x
on the plane sigma = 1), so when no (alpha, psi) beats the best pure rotation, alpha is not
determined (all alphas tie) and the estimate has ``angle=None`` (counted as "no estimate") but
keeps the rotation; "beats" means a strictly lower integer cost than the best pure rotation
over the psi values searched. A texture-less band gives :meth:`HomingEstimate.none`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from types import ModuleType
from typing import ClassVar, Literal

import numpy as np
from numpy.lib.stride_tricks import as_strided
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, wrap_angle
from homebench.imaging.horizon import band_elevations, horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register
from homebench.methods.warping import is_flat

FloatArray = NDArray[np.float64]
F32Array = NDArray[np.float32]
IntArray = NDArray[np.intp]
I64Array = NDArray[np.int64]
U16Array = NDArray[np.uint16]

#: rho samples per band column (over rho in [0, 1 + max_scale]) when tracing admissible pairs.
_RHO_SAMPLES_PER_COLUMN = 40
#: Goal columns traced at a time by :func:`search_template` (its arrays then stay in cache).
_TEMPLATE_BLOCK = 8
#: Largest entry of the quantised stack: distances are scaled so the pair's largest is this.
STACK_MAX = 65535

ColumnDistance = Literal["ssd", "sad", "zssd", "zsad", "nssd", "nsad", "znssd", "znsad"]


def magnification_matrix(elevations: FloatArray, scale: float) -> FloatArray:
    """Matrix (n, n) that magnifies a column sampled at ``elevations`` by ``scale >= 1``.

    Row r interpolates the column linearly at elevation ``atan(tan(e_r) / scale)``: an object at
    fixed height seen ``scale`` times closer. Needs the horizon (elevation 0) inside the band.
    """
    n = elevations.size
    source = np.arctan(np.tan(elevations) / scale)
    ascending = elevations[::-1]
    position = np.interp(source, ascending, np.arange(n)[::-1].astype(np.float64))
    low = np.clip(np.floor(position).astype(np.intp), 0, n - 1)
    high = np.minimum(low + 1, n - 1)
    frac = position - low
    matrix = np.zeros((n, n))
    np.add.at(matrix, (np.arange(n), low), 1.0 - frac)
    np.add.at(matrix, (np.arange(n), high), frac)
    return matrix


def column_distances(goal: FloatArray, current: FloatArray, distance: ColumnDistance) -> FloatArray:
    """Distance between every goal column and every current column: shape (n_goal, n_current).

    ``goal`` (rows, n_goal) and ``current`` (rows, n_current): columns over the band's rows. See
    the module docstring for the measures.
    """
    zero_mean, normalized = distance.startswith("z"), distance.lstrip("z").startswith("n")
    if zero_mean:
        goal = goal - goal.mean(axis=0)
        current = current - current.mean(axis=0)
    if distance.endswith("ssd"):
        size_g, size_c = np.sum(goal * goal, axis=0), np.sum(current * current, axis=0)
        joint = np.maximum(size_g[:, None] + size_c[None, :] - 2.0 * (goal.T @ current), 0.0)
    else:
        size_g, size_c = np.sum(np.abs(goal), axis=0), np.sum(np.abs(current), axis=0)
        joint = np.sum(np.abs(goal[:, :, None] - current[:, None, :]), axis=0)
    if not normalized:
        return joint
    total = size_g[:, None] + size_c[None, :]
    return np.divide(joint, total, out=np.zeros_like(joint), where=total > 0)


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
    """

    x_start: IntArray
    plane: IntArray
    y: IntArray
    run_start: IntArray
    run_plane: IntArray
    run_y: IntArray
    run_length: IntArray

    @property
    def run_level(self) -> IntArray:
        """floor(log2 run_length) of each run, (R,)."""
        return np.floor(np.log2(self.run_length)).astype(np.intp)

    @property
    def run_shift(self) -> IntArray:
        """run_length - 2**run_level of each run, (R,): the second window's offset."""
        return self.run_length - (1 << self.run_level)


@lru_cache(maxsize=8)
def search_template(n_columns: int, n_scales: int, max_scale: float) -> SearchTemplate:
    """Trace every goal column's admissible pairs over rho >= 0 (see the module docstring)."""
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
    run_table = np.array([run for x_runs in runs for run in x_runs], dtype=np.intp)
    return SearchTemplate(
        starts, plane, y_of, _starts([len(x_runs) for x_runs in runs]), *run_table.T
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


def quantize(stack: F32Array) -> U16Array:
    """``stack`` scaled so its largest entry is STACK_MAX and rounded: uint16, same shape."""
    top = float(stack.max())
    scale = STACK_MAX / top if top > 0 else 0.0
    return np.rint(stack.astype(np.float64) * scale).astype(np.uint16)


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


def rotation_costs(plane: U16Array, psis: IntArray) -> I64Array:
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


Engine = Literal["numba", "numpy"]


class _NumpySearch:
    """Costs by :func:`reference_costs` (the pure-numpy reading) on a stack (K, n, n)."""

    def __init__(self, stack: U16Array, template: SearchTemplate, step: int) -> None:
        self.stack, self.template, self.step = stack, template, step

    def coarse(self, swap: bool) -> I64Array:
        grid = self.step * np.arange(self.stack.shape[1] // self.step)
        return reference_costs(self._source(swap), self.template, grid, grid)

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        n, source = self.stack.shape[1], self._source(swap)
        pairs = zip(alphas % n, psis % n, strict=True)
        return np.array([reference_costs(source, self.template, [a], [p])[0, 0] for a, p in pairs])

    def _source(self, swap: bool) -> U16Array:
        return swapped(self.stack) if swap else self.stack


def _kernels() -> ModuleType:
    """The compiled kernels, imported by their first use: importing this module (as the
    command line does for every method) does not import numba."""
    from homebench.methods import min_warping_kernels

    return min_warping_kernels


class _CompiledSearch:
    """Costs by the numba kernels; the search tables of each view are built once."""

    def __init__(self, stack: U16Array, template: SearchTemplate, step: int) -> None:
        self.kernels = _kernels()
        self.stack, self.step, self.n = stack, step, stack.shape[1]
        self.runs = (
            template.run_start,
            template.run_plane,
            template.run_y,
            template.run_level,
            template.run_shift,
        )
        self.levels = int(template.run_level.max()) + 1
        self.tables: dict[bool, U16Array] = {}

    def coarse(self, swap: bool) -> I64Array:
        by_s = self.kernels.coarse_costs(self._table(swap), self.step, *self.runs)
        a = np.arange(self.n // self.step)[:, None]
        return by_s[(a - a.T) % by_s.shape[0], a]  # by_s is [alpha - psi, alpha]

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        return self.kernels.table_costs(self._table(swap), self.step, *self.runs, alphas, psis)

    def _table(self, swap: bool) -> U16Array:
        if swap not in self.tables:
            self.tables[swap] = self.kernels.search_table(self.stack, self.step, swap, self.levels)
        return self.tables[swap]


@register
@documented
@dataclass(frozen=True)
class MinWarping:
    """Min-warping; defaults: Möller's (288 band columns searched in 96 x 96 alpha, psi steps,
    double and fine search, 9 scale planes up to a factor 2, NSAD on vertically edge-filtered
    columns), on a band of 16 rows from -15 to +15 deg."""

    name: ClassVar[str] = "min-warping"
    image_kind: ClassVar[ImageKind] = "unfolded"
    preload_modules: ClassVar[tuple[str, ...]] = (
        "homebench.methods.min_warping_kernels",
        "homebench.methods.jit_setup",
    )

    n_columns: int = param(96, "Search steps of alpha and psi over a full turn (Möller: 96).")
    columns_per_step: int = param(
        3,
        "Band columns per alpha / psi step: the band has n_columns * columns_per_step columns "
        "(the fine search moves by single columns).",
        reading="Möller's SIMD code searches 288-column panoramas in 96 steps (3 columns a "
        "step); homebench searched a 96-column band before (columns_per_step=1)",
    )
    n_rows: int = param(
        16,
        "Rows of the band (>= 2 with edge_filter).",
        reading="the papers use the unfolded image's rows around the horizon at its own "
        "resolution; 16 rows (1.9 deg each) keep the distances cheap",
    )
    band_bottom_deg: float = param(
        -15.0,
        "Lower edge of the band (deg); the band must contain the horizon.",
        reading="the papers use the panorama's usable rows; a band around the horizon, where "
        "objects are at about camera height as the magnification model assumes",
    )
    band_top_deg: float = param(15.0, "Upper edge of the band (deg), as band_bottom_deg.")
    n_scales: int = param(9, "Scale planes (odd), sigma from 1 / max_scale to max_scale (Möller).")
    max_scale: float = param(2.0, "Largest vertical magnification searched (Möller).")
    distance: ColumnDistance = param(
        "nsad",
        "Column distance: ssd, sad, their zero-mean (z...), normalised (n...) or both (zn...) "
        "variants (see the module docstring).",
        reading="Möller et al. (2014) compare column distances for illumination tolerance; "
        "Möller's SIMD implementation defaults to NSAD on vertically edge-filtered columns, "
        "taken here as 'Möller's default' (homebench used ssd without the filter before)",
    )
    edge_filter: bool = param(
        True,
        "Filter each band vertically (difference of adjacent rows) before the distance; removes "
        "any offset of a column.",
        reading="the preprocessing of Möller's default NSAD, as distance",
    )
    double_search: bool = param(
        True,
        "Search again with goal and current view swapped and add the two costs at corresponding "
        "parameters (alpha' = alpha - psi + pi, psi' = -psi); needs an even n_columns.",
        reading="Möller's double search; his code averages the two 16-bit match arrays with "
        "rounding, the sum here keeps every tie exact",
    )
    fine_search: bool = param(
        True,
        "Refine the best (alpha, psi) step: every offset of up to columns_per_step - 1 band "
        "columns in alpha and psi around it (both views with double_search).",
        reading="Möller's fine search over the whole range to the neighbouring steps (his "
        "'surround' variant, half that range, is not offered)",
    )

    def __post_init__(self) -> None:
        check_fields(self)
        if self.n_columns < 4 or self.columns_per_step < 1 or self.n_rows < 1 + self.edge_filter:
            raise ConfigError(
                "min-warping: need n_columns >= 4, columns_per_step >= 1 and n_rows >= 1 "
                "(>= 2 with edge_filter)"
            )
        if self.double_search and self.n_columns % 2:
            raise ConfigError("min-warping: double_search needs an even n_columns")
        if not -90.0 < self.band_bottom_deg < 0.0 < self.band_top_deg < 90.0:
            raise ConfigError("min-warping: the band must contain the horizon (bottom < 0 < top)")
        if self.n_scales < 3 or self.n_scales % 2 == 0 or not self.max_scale > 1.0:
            raise ConfigError("min-warping: n_scales must be odd >= 3 and max_scale > 1")

    @property
    def band_columns(self) -> int:
        """Columns of the band: n_columns * columns_per_step."""
        return self.n_columns * self.columns_per_step

    @property
    def scales(self) -> FloatArray:
        """Scale factors sigma of the planes, (n_scales,), increasing, the middle one 1."""
        h = (self.n_scales - 1) // 2
        return self.max_scale ** (np.arange(-h, h + 1) / h)

    @property
    def template(self) -> SearchTemplate:
        """The admissible pairs of every goal column of the band (cached per shape)."""
        return search_template(self.band_columns, self.n_scales, self.max_scale)

    def describe(self, view: View) -> F32Array:
        """Band (edge-filtered: rows - 1 rows) magnified by sigma = 1 .. max_scale: shape
        (h + 1, rows, band_columns), float32."""
        bottom, top = np.radians(self.band_bottom_deg), np.radians(self.band_top_deg)
        band = horizon_band(view.image, view.geometry, bottom, top, self.n_rows, self.band_columns)
        elevations = band_elevations(bottom, top, self.n_rows)
        if self.edge_filter:
            band = band[:-1] - band[1:]
            elevations = 0.5 * (elevations[:-1] + elevations[1:])
        h = (self.n_scales - 1) // 2
        stack = [magnification_matrix(elevations, s) @ band for s in self.scales[h:]]
        return np.stack(stack).astype(np.float32)

    def distance_stack(self, current: F32Array, goal: F32Array) -> F32Array:
        """Scale-plane stack D (n_scales, n, n): [plane, goal col, current col], pure numpy."""
        h = (self.n_scales - 1) // 2
        goal64, current64 = goal.astype(np.float64), current.astype(np.float64)
        planes = [
            column_distances(
                *((goal64[m], current64[0]) if m >= 0 else (goal64[0], current64[-m])),
                self.distance,
            )
            for m in range(-h, h + 1)
        ]
        return np.stack(planes).astype(np.float32)

    def quantized_stack(self, current: F32Array, goal: F32Array, engine: Engine) -> U16Array:
        """The stack D in 16 bits (see the module docstring), by numpy or the compiled kernel."""
        if engine == "numpy":
            return quantize(self.distance_stack(current, goal))
        if self.distance.startswith("z"):
            goal = goal - goal.mean(axis=1, keepdims=True)
            current = current - current.mean(axis=1, keepdims=True)
        squared = self.distance.endswith("ssd")
        sizes = [np.sum(v * v if squared else np.abs(v), axis=1) for v in (goal, current)]
        normalized = self.distance.lstrip("z").startswith("n")
        kernels = _kernels()
        planes = kernels.distance_planes(goal, current, *sizes, squared, normalized)
        return kernels.quantize(planes, float(planes.max()))

    def searcher(self, stack: U16Array, engine: Engine) -> _NumpySearch | _CompiledSearch:
        """Cost evaluation on ``stack`` by the compiled kernels or the numpy reference."""
        kind = _CompiledSearch if engine == "numba" else _NumpySearch
        return kind(stack, self.template, self.columns_per_step)

    def coarse(self, stack: U16Array, engine: Engine, swap: bool = False) -> I64Array:
        """Cost of every (alpha, psi) step on ``stack`` (or its swapped reading): shape
        (n_columns, n_columns), [alpha step, psi step]."""
        return self.searcher(stack, engine).coarse(swap)

    def search(self, stack: U16Array, engine: Engine = "numba") -> tuple[int, int, int, IntArray]:
        """Best (cost, alpha, psi) in band columns, and the psi columns searched (m,)."""
        n, step, columns = self.n_columns, self.columns_per_step, self.band_columns
        searcher = self.searcher(stack, engine)
        cost = searcher.coarse(False)
        if self.double_search:
            a = np.arange(n)[:, None]
            cost = cost + searcher.coarse(True)[(a - a.T + n // 2) % n, -a.T % n]
        a, p = np.unravel_index(int(np.argmin(cost)), cost.shape)
        best, alpha, psi = int(cost[a, p]), step * int(a), step * int(p)
        psis = step * np.arange(n)
        if self.fine_search and step > 1:
            d_psi, d_alpha = np.divmod(np.arange((2 * step - 1) ** 2), 2 * step - 1)
            d_psi, d_alpha = d_psi - (step - 1), d_alpha - (step - 1)
            costs = self.costs_at(searcher, alpha + d_alpha, psi + d_psi)  # psi-major order
            pick = int(np.argmin(costs))
            best, alpha, psi = int(costs[pick]), alpha + int(d_alpha[pick]), psi + int(d_psi[pick])
            psis = np.concatenate([psis, (psi - d_psi[pick] + np.arange(1 - step, step)) % columns])
        return best, alpha % columns, psi % columns, psis

    def costs_at(
        self, searcher: _NumpySearch | _CompiledSearch, alphas: IntArray, psis: IntArray
    ) -> I64Array:
        """Costs (m,) of (alpha, psi) pairs in band columns (both views with double_search)."""
        costs = searcher.at(alphas, psis, False)
        if self.double_search:
            costs = costs + searcher.at(alphas - psis + self.band_columns // 2, -psis, True)
        return costs

    def home(self, current: F32Array, goal: F32Array, engine: Engine = "numba") -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (alpha, psi); ``engine``: the
        compiled kernels or the pure-numpy reference (same result)."""
        if current.shape != goal.shape:
            raise ValueError("min-warping: features of different shapes")
        if is_flat(current[0]) or is_flat(goal[0]):
            return HomingEstimate.none(n_landmarks=self.band_columns, reason="no texture")
        n = self.band_columns
        stack = self.quantized_stack(current, goal, engine)
        best, a, p, psis = self.search(stack, engine)
        # pure rotations by the searched psis: y = x on the unit plane, both views alike
        rotation = rotation_costs(stack[(self.n_scales - 1) // 2], psis)
        rotation *= 1 + self.double_search
        psi_only = int(psis[np.argmin(rotation)])
        if best >= rotation.min():
            psi = float(wrap_angle(TWO_PI * psi_only / n))
            return HomingEstimate(
                angle=None,
                rotation=psi,
                n_landmarks=n,
                score=float(rotation.min()),
                diagnostics={"alpha": None, "psi": psi},
            )
        alpha, psi = TWO_PI * a / n, float(wrap_angle(TWO_PI * p / n))
        return HomingEstimate(
            angle=float(wrap_angle(alpha - psi + np.pi)),
            rotation=psi,
            n_landmarks=n,
            score=float(best),
            diagnostics={"alpha": float(alpha), "psi": psi},
        )
