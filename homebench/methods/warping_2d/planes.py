"""2D-warping on min-warping's scale-plane stack: the scheme Möller's SIMD code runs as
"2D-warping" (warping-2d's ``scheme="scale-planes"``).

The model is 2D-warping's (see :mod:`homebench.methods.warping_2d.method`): the robot left the goal
in
direction ``alpha`` for ``rho`` landmark distances and turned by ``psi``, every landmark at one
distance from the goal. The image distance is min-warping's instead of the warped band's: the
scale-plane stack ``D[k, i, j]`` of :mod:`homebench.methods.min_warping.method` (goal column i
against
current column j, one of them magnified vertically by the plane's factor sigma_k; NSAD of
vertically edge-filtered columns by default), so a hypothesis costs one stack entry per goal
column. Goal offset x (band columns from alpha, angle ``x`` radians) is seen from the current
place at offset ``y = atan2(sin x, cos x - rho)`` (also from alpha) and magnified by ``sigma =
1 / sqrt(1 - 2 rho cos x + rho**2)``: the template (:func:`plane_template`) holds, for every
searched rho and goal offset, the current offset (nearest column) and the plane (nearest in
log sigma, as min-warping's admissible pairs; beyond ``max_scale`` the outermost plane, as in
Möller's template, whose outermost thresholds are unbounded). At ``rho = 1`` the goal offset
x = 0 has the robot on its landmark: infinite magnification (the outermost plane) and an
undefined direction, taken a quarter turn from x as Möller's template takes it (between 0 and
pi). One reading differs from that template: a plane is chosen as the nearest in log sigma
(min-warping's rule), where Möller's thresholds lie at the arithmetic means of neighbouring
scale factors. The cost of (alpha, psi) is

    ``min over rho of sum over x of D[plane[rho, x], x + alpha, y[rho, x] + alpha - psi]``

(columns modulo the band), where min-warping takes the minimum over rho per goal column, before
the sum. Möller's code evaluates the same sums (its ``WarpingFull_PARX``: psi, alpha, rho, x);
its template follows Möller, Krzykawski & Gerstmayr (2010, "Three 2D-warping schemes for visual
robot navigation", eqs. 1 and 4, as its source cites them). Double search, fine search, the
integer costs and the "no direction without evidence" rule are min-warping's
(:class:`ScalePlaneWarping2D` is min-warping with this search): with ``rho = 0`` on the grid
every alpha can explain a pure rotation, so a direction needs a strictly lower cost than the
best pure rotation.

:func:`reference_costs` is the pure-numpy search (every entry looked up), which the compiled
search (:class:`CompiledPlaneSearch`, :mod:`homebench.methods.warping_2d.plane_kernels`) is
tested against: both return the same integers.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from types import ModuleType
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import TWO_PI
from homebench.methods.min_warping.method import Engine, MinWarping
from homebench.methods.min_warping.search import CostSearch, NumpySearch, new_owner, workspace
from homebench.methods.min_warping.search import kernels as min_warping_kernels

IntArray = NDArray[np.intp]
I64Array = NDArray[np.int64]
U8Array = NDArray[np.uint8]


@dataclass(frozen=True)
class PlaneTemplate:
    """Where each goal offset x is seen under each searched rho: ``plane[r, x]`` (0 ..
    n_scales - 1, sigma increasing) and current offset ``y[r, x]`` (columns from alpha, 0 ..
    n - 1); both (n_rho, n), contiguous."""

    plane: IntArray
    y: IntArray


@lru_cache(maxsize=8)
def plane_template(
    n_columns: int, rho: tuple[float, ...], n_scales: int, max_scale: float
) -> PlaneTemplate:
    """The equal-distance template of a band of ``n_columns`` columns (see the module
    docstring); ``rho`` values in [0, 1]."""
    h = (n_scales - 1) // 2
    x = (TWO_PI / n_columns) * np.arange(n_columns)[None, :]
    r = np.asarray(rho, dtype=np.float64)[:, None]
    distance2 = 1.0 - 2.0 * r * np.cos(x) + r**2  # (current distance / goal distance)**2
    on_it = distance2 <= 0.0  # rho = 1, x = 0: the robot stands on the landmark
    with np.errstate(divide="ignore"):
        m = -0.5 * h * np.log(np.where(on_it, 1.0, distance2)) / np.log(max_scale)
    m = np.where(on_it, h, np.clip(np.rint(m), -h, h)).astype(np.intp)
    # there the landmark's direction is undefined (0 or pi): a quarter turn, as Möller's
    # template takes the value between
    y = np.where(on_it, x + 0.5 * np.pi, np.arctan2(np.sin(x), np.cos(x) - r))
    column = np.rint(y * (n_columns / TWO_PI)).astype(np.intp) % n_columns
    return PlaneTemplate(np.ascontiguousarray(m + h), np.ascontiguousarray(column))


def reference_costs(
    stack: U8Array, template: PlaneTemplate, alphas: IntArray, psis: IntArray
) -> I64Array:
    """Pure-numpy search: cost (len(alphas), len(psis)) of (alpha, psi) in columns on ``stack``
    (n_scales, n, n) [plane, goal col, current col], int64."""
    n = stack.shape[1]
    psis = np.asarray(psis)
    cost = np.empty((len(alphas), len(psis)), dtype=np.int64)
    for row, alpha in enumerate(alphas):
        goal = (np.arange(n) + alpha) % n
        current = (template.y[:, :, None] + alpha - psis[None, None, :]) % n
        values = stack[template.plane[:, :, None], goal[None, :, None], current]
        cost[row] = values.sum(axis=1, dtype=np.int64).min(axis=0)
    return cost


def plane_kernels() -> ModuleType:
    """The compiled kernels, imported by their first use (not by importing this module)."""
    from homebench.methods.warping_2d import plane_kernels

    return plane_kernels


class CompiledPlaneSearch:
    """Costs by the numba kernels, as :func:`reference_costs` gives them (a
    :class:`~homebench.methods.min_warping.search.CostSearch`): the coarse search reads the
    stack laid out by min-warping's :func:`~homebench.methods.min_warping.kernels.search_table`
    (its level 0 only: goal columns of consecutive alpha steps side by side), built once per
    reading into this thread's workspace; the pairs of the fine search read the stack."""

    def __init__(self, stack: U8Array, template: PlaneTemplate, step: int) -> None:
        self.kernels, self.workspace, self.owner = plane_kernels(), workspace(), new_owner()
        self.stack, self.template, self.step = stack, template, step
        n = stack.shape[1]
        self.shape = (1, step * stack.shape[0] * n, n // step)

    def coarse(self, swap: bool) -> I64Array:
        """Cost of every (alpha, psi) step: (n_steps, n_steps), [alpha step, psi step]."""
        table, built = self.workspace.array(f"plane table {swap}", self.shape, np.uint8, self.owner)
        if not built:
            min_warping_kernels().search_table(self.stack, self.step, swap, table)
        return self.kernels.coarse_costs(table[0], self.step, self.template.plane, self.template.y)

    def at(self, alphas: IntArray, psis: IntArray, swap: bool) -> I64Array:
        """Costs (m,) of (alpha, psi) pairs (m,) in band columns."""
        indices = (np.ascontiguousarray(v, dtype=np.intp) for v in (alphas, psis))
        return self.kernels.pair_costs(
            self.stack, swap, self.template.plane, self.template.y, *indices
        )


@dataclass(frozen=True)
class ScalePlaneWarping2D(MinWarping):
    """Min-warping's features, stack, double and fine search and estimate, with the
    equal-distance search over ``rho`` (see the module docstring); warping-2d's
    ``scheme="scale-planes"`` builds it from its own parameters."""

    name: ClassVar[str] = "warping-2d"

    rho: tuple[float, ...] = (0.0,)

    @property
    def plane_template(self) -> PlaneTemplate:
        """The template of the band (cached per shape)."""
        return plane_template(self.band_columns, self.rho, self.n_scales, self.max_scale)

    def searcher(self, stack: U8Array, engine: Engine) -> CostSearch:
        """Cost evaluation on ``stack`` by the compiled kernels or the numpy reference."""
        if engine == "numba":
            return CompiledPlaneSearch(stack, self.plane_template, self.columns_per_step)
        return NumpySearch(stack, self.plane_template, self.columns_per_step, reference_costs)
