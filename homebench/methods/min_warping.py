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
2. **Search**: for every (alpha, psi) in whole columns and every goal column, the minimum of D
   over the (current column, scale plane) pairs that some ``rho >= 0`` produces (current column
   and scale quantised to the nearest column / plane; scales beyond ``max_scale`` are not
   searched), summed over the goal columns; the best (alpha, psi) wins and
   ``beta = alpha - psi + pi``. Möller's double search (snapshot and current view swapped) and
   fine search are not implemented.

For speed the admissible (y, plane) pairs of each ``x`` are grouped into runs of consecutive
columns on one plane, and the minimum of D over every run length is precomputed (a running
minimum along the current columns), so each (alpha, psi, goal column) needs one look-up per run
instead of one per admissible column.

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
keeps the rotation; "beats" means by more than a relative ``TIE_TOLERANCE`` (rounding). A
texture-less band gives :meth:`HomingEstimate.none`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar, Literal

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, wrap_angle
from homebench.imaging.horizon import band_elevations, horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View
from homebench.methods.params import check_choices, documented, param
from homebench.methods.registry import register
from homebench.methods.warping import is_flat

FloatArray = NDArray[np.float64]
F32Array = NDArray[np.float32]
IntArray = NDArray[np.intp]

#: rho samples per goal column when tracing its admissible (current column, scale) pairs.
_RHO_SAMPLES = 4001
#: Relative margin by which the best warp must beat the best pure rotation to give a direction.
TIE_TOLERANCE = 1e-9

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
class SearchRuns:
    """Admissible (current column, scale plane) pairs of each goal column, as runs.

    Goal column offsets ``x`` (columns from alpha, shape (n_columns,)) are sorted by decreasing
    number of runs ``count``; run q of row r covers current offsets ``start[r, q] ..
    start[r, q] + length[r, q] - 1`` (mod n, columns from alpha) on scale plane ``plane[r, q]``
    (0 .. n_scales - 1, sigma increasing). Arrays are (n_columns, max runs); entries with
    ``q >= count[r]`` are unused.
    """

    x: IntArray
    count: IntArray
    length: IntArray
    plane: IntArray
    start: IntArray


@lru_cache(maxsize=8)
def search_runs(n_columns: int, n_scales: int, max_scale: float) -> SearchRuns:
    """Trace every goal column's admissible pairs over rho >= 0 and group them into runs."""
    h = (n_scales - 1) // 2
    rho = np.linspace(0.0, 1.0 + max_scale, _RHO_SAMPLES)
    step = TWO_PI / n_columns
    per_x: list[list[tuple[int, int, int]]] = []
    for x_col in range(n_columns):
        x = x_col * step
        distance2 = 1.0 - 2.0 * rho * np.cos(x) + rho**2
        ok = distance2 > 1e-12
        y = np.arctan2(np.sin(x), np.cos(x) - rho[ok])
        m = np.rint(-0.5 * h * np.log(distance2[ok]) / np.log(max_scale)).astype(np.intp)
        inside = np.abs(m) <= h
        y_col = np.rint(y[inside] / step).astype(np.intp) % n_columns
        pairs = np.unique(np.stack([m[inside] + h, y_col], axis=1), axis=0)
        per_x.append(_runs(pairs, n_columns))
    count = np.array([len(r) for r in per_x])
    order = np.argsort(-count, kind="stable")
    table = np.zeros((n_columns, int(count.max()), 3), dtype=np.intp)
    for row, x_col in enumerate(order):
        table[row, : count[x_col]] = per_x[x_col]
    return SearchRuns(order, count[order], table[..., 0], table[..., 1], table[..., 2])


def _runs(pairs: IntArray, n_columns: int) -> list[tuple[int, int, int]]:
    """Group sorted unique (plane, column) pairs into circular runs (length, plane, start)."""
    runs: list[tuple[int, int, int]] = []
    for plane in np.unique(pairs[:, 0]):
        cols = pairs[pairs[:, 0] == plane, 1]
        breaks = np.flatnonzero(np.diff(cols) != 1) + 1
        groups = [list(g) for g in np.split(cols, breaks)]
        if len(groups) > 1 and groups[0][0] == 0 and groups[-1][-1] == n_columns - 1:
            groups[0] = groups.pop() + groups[0]  # the run wraps past the last column
        runs.extend((len(g), int(plane), int(g[0])) for g in groups)
    return runs


@register
@documented
@dataclass(frozen=True)
class MinWarping:
    """Min-warping; defaults: Möller's (96 x 96 alpha, psi steps, 9 scale planes up to a factor
    2, NSAD on vertically edge-filtered columns), on a band of 16 rows from -15 to +15 deg."""

    name: ClassVar[str] = "min-warping"
    image_kind: ClassVar[ImageKind] = "unfolded"

    n_columns: int = param(
        96, "Columns of the band; alpha and psi are searched in whole columns (Möller: 96)."
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

    def __post_init__(self) -> None:
        check_choices(self)
        if self.n_columns < 4 or self.n_rows < 1 + self.edge_filter:
            raise ConfigError(
                "min-warping: need n_columns >= 4 and n_rows >= 1 (>= 2 with edge_filter)"
            )
        if not -90.0 < self.band_bottom_deg < 0.0 < self.band_top_deg < 90.0:
            raise ConfigError("min-warping: the band must contain the horizon (bottom < 0 < top)")
        if self.n_scales < 3 or self.n_scales % 2 == 0 or not self.max_scale > 1.0:
            raise ConfigError("min-warping: n_scales must be odd >= 3 and max_scale > 1")

    @property
    def scales(self) -> FloatArray:
        """Scale factors sigma of the planes, (n_scales,), increasing, the middle one 1."""
        h = (self.n_scales - 1) // 2
        return self.max_scale ** (np.arange(-h, h + 1) / h)

    def describe(self, view: View) -> F32Array:
        """Band (edge-filtered: rows - 1 rows) magnified by sigma = 1 .. max_scale: shape
        (h + 1, rows, n_columns), float32."""
        bottom, top = np.radians(self.band_bottom_deg), np.radians(self.band_top_deg)
        band = horizon_band(view.image, view.geometry, bottom, top, self.n_rows, self.n_columns)
        elevations = band_elevations(bottom, top, self.n_rows)
        if self.edge_filter:
            band = band[:-1] - band[1:]
            elevations = 0.5 * (elevations[:-1] + elevations[1:])
        h = (self.n_scales - 1) // 2
        stack = [magnification_matrix(elevations, s) @ band for s in self.scales[h:]]
        return np.stack(stack).astype(np.float32)

    def distance_stack(self, current: F32Array, goal: F32Array) -> F32Array:
        """Scale-plane stack D (n_scales, n_columns, n_columns): [plane, goal col, current col]."""
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

    def costs(self, distances: F32Array) -> FloatArray:
        """Min-warping cost of every (alpha, psi) in columns: shape (n_columns, n_columns)."""
        n = self.n_columns
        runs = search_runs(n, self.n_scales, self.max_scale)
        # Reversed, tripled current-column axis: wide[..., u] = D[..., (n - u) % n].
        wide = distances[..., (n - np.arange(3 * n)) % n]
        # table[L - 1, k, i, w] = min over t < L of D[k, i, (t - w) % n], w in [0, 2n)
        table = np.empty((int(runs.length.max()),) + distances.shape[:2] + (2 * n,), np.float32)
        table[0] = wide[..., n : 3 * n]
        for t in range(1, table.shape[0]):
            np.minimum(table[t - 1], wide[..., n - t : 3 * n - t], out=table[t])
        windows = sliding_window_view(table, n, axis=-1)  # (L, k, i, w, psi)
        a = np.arange(n)[:, None]  # alpha column; index arrays below are (alpha, x)
        best = np.empty((n, n, n), dtype=np.float32)  # (alpha, x, psi)
        for q in range(runs.length.shape[1]):
            k = int(np.count_nonzero(runs.count > q))  # rows are sorted by run count
            # goal column i = x + alpha; current column j = y + alpha - psi, y = start + t;
            # window w = -(start + alpha) reads D[..., (t + start + alpha - psi) % n] at psi.
            rows = windows[
                runs.length[:k, q] - 1,
                runs.plane[:k, q],
                (runs.x[:k] + a) % n,
                -(runs.start[:k, q] + a) % n,
            ]
            if q == 0:
                best[...] = rows
            else:
                np.minimum(best[:, :k], rows, out=best[:, :k])
        return best.sum(axis=1, dtype=np.float64)

    def home(self, current: F32Array, goal: F32Array) -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (alpha, psi)."""
        if current.shape != goal.shape:
            raise ValueError("min-warping: features of different shapes")
        if is_flat(current[0]) or is_flat(goal[0]):
            return HomingEstimate.none(n_landmarks=self.n_columns, reason="no texture")
        n = self.n_columns
        distances = self.distance_stack(current, goal)
        cost = self.costs(distances)
        a, p = np.unravel_index(int(np.argmin(cost)), cost.shape)
        unit = (self.n_scales - 1) // 2
        i = np.arange(n)
        rotation_only = distances[unit, i[None, :], (i[None, :] - i[:, None]) % n].sum(
            axis=1, dtype=np.float64
        )  # (psi,)
        psi_only = int(np.argmin(rotation_only))
        best = float(cost[a, p])
        if best >= rotation_only[psi_only] * (1.0 - TIE_TOLERANCE):
            psi = float(wrap_angle(TWO_PI * psi_only / n))
            return HomingEstimate(
                angle=None,
                rotation=psi,
                n_landmarks=n,
                score=float(rotation_only[psi_only]),
                diagnostics={"alpha": None, "psi": psi},
            )
        alpha, psi = TWO_PI * a / n, float(wrap_angle(TWO_PI * p / n))
        return HomingEstimate(
            angle=float(wrap_angle(alpha - psi + np.pi)),
            rotation=psi,
            n_landmarks=n,
            score=best,
            diagnostics={"alpha": float(alpha), "psi": psi},
        )
