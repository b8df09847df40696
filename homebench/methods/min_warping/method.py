"""Möller's min-warping (Möller 2009; Möller, Krzykawski, Gerstmayr 2010) on the horizon band.

Same movement model as 1-D warping (see :mod:`homebench.methods.warping.method`): the robot left the
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

**Integers.** The stack is kept in 8 bits, as the test programs of Möller's SIMD code run it
(``warpingSIMDTest``: an 8-bit scale-plane stack, ``SPSTYPE SIMDByte``, summed into 16-bit match
values, ``MATCHTYPE SIMDWord``): each pair's float stack is scaled so its largest entry is 255
and rounded (``quantize``; his code scales NSAD by a fixed 200 instead, which only a bounded
measure allows); costs are exact integer sums (int64), so ties and the optimum do not depend
on summation order. The search runs in compiled kernels
(:mod:`homebench.methods.min_warping.kernels`, numba: goal column first, the running minima of
all alphas of one (goal column, psi) in one vector; each run of consecutive admissible current
columns on one plane answered by two look-ups in a table of windowed minima, see
:mod:`homebench.methods.min_warping.search`); :func:`~homebench.methods.min_warping.search.
reference_costs` and :meth:`MinWarping.distance_stack` are the pure-numpy reading they are
tested against (``home(..., engine="numpy")`` gives the same estimate). homebench kept a 16-bit
stack before (said to be Möller's); over all 28,730 pairs of a generated 10 x 17 grid (288 x 72,
seed 0) the 8-bit stack changes 300 estimates and the mean AE from 1.390 to 1.384 deg (per goal
-0.006 deg, 95 % interval over the goals [-0.016, 0.001]), and halves the search's memory
traffic.

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
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, wrap_angle
from homebench.imaging.horizon import band_elevations, horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View, is_flat
from homebench.methods.min_warping.search import (
    CompiledSearch,
    CostSearch,
    NumpySearch,
    SearchTemplate,
    kernels,
    new_owner,
    rotation_costs,
    search_template,
    workspace,
)
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]
F32Array = NDArray[np.float32]
IntArray = NDArray[np.intp]
U8Array = NDArray[np.uint8]
I64Array = NDArray[np.int64]

#: Largest entry of the quantised stack: distances are scaled so the pair's largest is this.
STACK_MAX = 255

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


def quantize(stack: F32Array) -> U8Array:
    """``stack`` scaled so its largest entry is STACK_MAX and rounded: uint8, same shape."""
    top = float(stack.max())
    scale = STACK_MAX / top if top > 0 else 0.0
    return np.rint(stack.astype(np.float64) * scale).astype(np.uint8)


Engine = Literal["numba", "numpy"]


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
        "homebench.methods.min_warping.kernels",
        "homebench.methods.min_warping.preload",
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
        "variants (see homebench.methods.min_warping.method).",
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
                f"{self.name}: need n_columns >= 4, columns_per_step >= 1 and n_rows >= 1 "
                "(>= 2 with edge_filter)"
            )
        if self.double_search and self.n_columns % 2:
            raise ConfigError(f"{self.name}: double_search needs an even n_columns")
        if not -90.0 < self.band_bottom_deg < 0.0 < self.band_top_deg < 90.0:
            raise ConfigError(f"{self.name}: the band must contain the horizon (bottom < 0 < top)")
        if self.n_scales < 3 or self.n_scales % 2 == 0 or not self.max_scale > 1.0:
            raise ConfigError(f"{self.name}: n_scales must be odd >= 3 and max_scale > 1")

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

    def quantized_stack(
        self, current: F32Array, goal: F32Array, engine: Engine, out: U8Array | None = None
    ) -> U8Array:
        """The stack D in 8 bits (see the module docstring), by numpy or the compiled kernels
        (which write it into ``out``, (n_scales, n, n) uint8, when given)."""
        if engine == "numpy":
            return quantize(self.distance_stack(current, goal))
        if self.distance.startswith("z"):
            goal = goal - goal.mean(axis=1, keepdims=True)
            current = current - current.mean(axis=1, keepdims=True)
        squared = self.distance.endswith("ssd")
        sizes = [np.sum(v * v if squared else np.abs(v), axis=1) for v in (goal, current)]
        normalized = self.distance.lstrip("z").startswith("n")
        shape = (self.n_scales, goal.shape[2], goal.shape[2])
        planes, _ = workspace().array("planes", shape, np.float32, new_owner())
        compiled = kernels()
        top = compiled.distance_planes(goal, current, *sizes, squared, normalized, planes)
        out = np.empty(shape, dtype=np.uint8) if out is None else out
        compiled.quantize(planes, float(top), out)
        return out

    def searcher(self, stack: U8Array, engine: Engine) -> CostSearch:
        """Cost evaluation on ``stack`` by the compiled kernels or the numpy reference."""
        kind = CompiledSearch if engine == "numba" else NumpySearch
        return kind(stack, self.template, self.columns_per_step)

    def coarse(self, stack: U8Array, engine: Engine, swap: bool = False) -> I64Array:
        """Cost of every (alpha, psi) step on ``stack`` (or its swapped reading): shape
        (n_columns, n_columns), [alpha step, psi step]."""
        return self.searcher(stack, engine).coarse(swap)

    def search(self, stack: U8Array, engine: Engine = "numba") -> tuple[int, int, int, IntArray]:
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

    def costs_at(self, searcher: CostSearch, alphas: IntArray, psis: IntArray) -> I64Array:
        """Costs (m,) of (alpha, psi) pairs in band columns (both views with double_search)."""
        costs = searcher.at(alphas, psis, False)
        if self.double_search:
            costs = costs + searcher.at(alphas - psis + self.band_columns // 2, -psis, True)
        return costs

    def home(self, current: F32Array, goal: F32Array, engine: Engine = "numba") -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (alpha, psi); ``engine``: the
        compiled kernels or the pure-numpy reference (same result)."""
        if current.shape != goal.shape:
            raise ValueError(f"{self.name}: features of different shapes")
        if is_flat(current[0]) or is_flat(goal[0]):
            return HomingEstimate.none(n_landmarks=self.band_columns, reason="no texture")
        n = self.band_columns
        buffer = None
        if engine == "numba":
            buffer, _ = workspace().array("stack", (self.n_scales, n, n), np.uint8, new_owner())
        stack = self.quantized_stack(current, goal, engine, buffer)
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
