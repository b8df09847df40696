"""Möller's (2009) 2D-warping: 1-D warping's search on the two-dimensional horizon band.

Möller, R. (2009). Local visual homing by warping of two-dimensional images. Robotics and
Autonomous Systems 57(1), 87-101.

Model: 1-D warping's (see :mod:`homebench.methods.warping.method`): the robot left the goal in
direction ``alpha`` for ``rho`` landmark distances and turned by ``psi``, all landmarks at one
distance from the goal (the equal-distance assumption). In two dimensions a landmark moves in
azimuth AND changes its distance, so each column of the goal image is also scaled vertically:
a landmark at unit distance from the goal, seen from the current place at (rotated) azimuth
``phi``, lies at distance ``r' = -rho cos(phi - alpha) + sqrt(1 - rho**2 sin**2(phi - alpha))``
there; a point at height ``h`` above the camera is seen under elevation ``atan(h)`` at the
goal and ``atan(h / r')`` at the current place. The predicted current image at (phi, elevation
e) is therefore the goal image at azimuth ``theta = phi - arcsin(rho sin(phi - alpha))`` (1-D
warping's tables, :func:`homebench.methods.warping.method.warp_tables`) and elevation
``atan(tan(e) * r')``, rotated by psi. The search minimises the image distance over (rho,
alpha, psi) and the home direction is ``beta = alpha - psi + pi`` (current robot frame).

Implementation: each view is described by its band (``n_rows`` rows from ``band_bottom_deg``
to ``band_top_deg``) plus margin rows above and below with the same row height, so the goal can
be sampled at the elevations a shrinking column needs (``r' > 1``: up to
``atan(tan(top) * (1 + rho_max))``; margins are limited to the panorama, and samples beyond
them take the nearest stored row). The warped goal is interpolated bilinearly (columns as in
1-D warping, then rows). Psi runs over whole columns: the distance of every psi is one
cross-correlation per (rho, alpha), by FFT: the warped goals' spectra times the conjugate
spectrum of the current band, summed over the rows (each product as ``(wr br + wi bi) + (wi br
- wr bi) i``, rows summed from the first: numpy's complex product may fuse its operations
where the CPU can, and its result would then depend on the CPU).

Speed: what depends on the goal alone (the warped goals, 1,920 x 16 x 96 at the defaults,
their spectra and energies: :class:`GoalPart`) is computed once per goal and kept for the
last :data:`GOAL_CACHE_SIZE` goals, by the goal features' bytes (a job homes every current
view to one goal); a pair then costs the row sums of the spectra, in a compiled kernel
(:mod:`homebench.methods.warping_2d.kernels`), one inverse FFT per (rho, alpha) and the
argmin. ``engine="numpy"`` computes everything afresh in numpy, the reference the compiled
path is tested against: both give the same float64 costs bit for bit.

Readings (see the parameters): the band and its resolution are min-warping's (the same paper
introduces both methods), alpha and psi in whole columns of the band; the rho grid is 1-D
warping's (Franz et al. 1998, Table 1: 20 steps up to 0.95); the image distance is the sum of
squared differences.
``rho = 0`` carries no direction (every alpha gives the same warp): the estimate then has
``angle=None`` but keeps the rotation. A texture-less band gives :meth:`HomingEstimate.none`.

Scheme (option ``scheme``, default ``"image"``, the reading above): ``"scale-planes"`` runs
the same model the way Möller's SIMD code runs 2D-warping, on min-warping's scale-plane stack
(:mod:`homebench.methods.warping_2d.planes`): each goal column costs the stack entry of its
current column and vertical scale (both quantised), the column distance is min-warping's (NSAD
of vertically edge-filtered columns by default), its double and fine search apply, and rho runs
from 0 to 1 as in that code (``rho_max=None`` takes each scheme's grid). Min-warping's
parameters for it are listed here as "Scheme 'scale-planes' only." Measured against that code
(``benchmarks/bench_warping_2d.py --peer``, a generated 10 x 17 grid of 288 x 72 panoramas): the
same AE, 5.31 deg against its 5.34 over 15 goals (difference -0.03 deg, 95 % goal-bootstrap
interval [-0.38, 0.30]); on goal (5, 9) 1.23 deg against 1.23, where the image scheme has 2.70,
at 1.14-1.21x its CPU per pair.

Paper look-up (issue 14): Möller's (2009) rho grid is not in reach here: the searched public
pages hold no text of the paper (searches for its title and for the warping parameter grid
found unrelated image-warping pages). Chosen as 1-D warping's grid (option ``n_rho``), to be
checked against the paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import lru_cache
from types import ModuleType
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View, is_flat
from homebench.methods.min_warping.method import ColumnDistance, MinWarping
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param, same_as
from homebench.methods.registry import register
from homebench.methods.warping.method import best_hypothesis, rho_grid, warp_tables
from homebench.methods.warping_2d.planes import ScalePlaneWarping2D

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
IntArray = NDArray[np.intp]
Engine = Literal["numba", "numpy"]

#: Goals whose :class:`GoalPart` one method instance keeps (24 MB each at the defaults).
GOAL_CACHE_SIZE = 2

Scheme = Literal["image", "scale-planes"]
#: Min-warping's parameters that warping-2d takes for its scheme "scale-planes" (only).
SCALE_PLANE_PARAMETERS = (
    "columns_per_step",
    "n_scales",
    "max_scale",
    "distance",
    "edge_filter",
    "double_search",
    "fine_search",
)
_PLANES_ONLY = "Scheme 'scale-planes' only."
#: Each scheme's rho_max when it is None (see the parameter).
SCHEME_RHO: dict[str, float] = {"image": 0.95, "scale-planes": 1.0}


def _min_warping(name: str) -> object:
    """Min-warping's default of its parameter ``name``."""
    return next(f.default for f in fields(MinWarping) if f.name == name)


def landmark_distance(rho: FloatArray, offset: FloatArray) -> FloatArray:
    """Distance from the current place to a landmark on the unit circle around the goal, seen
    at angle ``offset = phi - alpha`` from the movement direction (0 <= rho < 1; broadcasts)."""
    return -rho * np.cos(offset) + np.sqrt(1.0 - (rho * np.sin(offset)) ** 2)


@lru_cache(maxsize=8)
def row_tables(
    n_columns: int, rho: tuple[float, ...], n_alpha: int, elevations: tuple[float, ...], margin: int
) -> tuple[IntArray, FloatArray]:
    """Linear-interpolation tables of the vertical warp, each of shape (n_rho * n_alpha,
    n_columns, n_rows).

    ``elevations``: centres of the band's rows (radians, descending, evenly spaced); the stored
    image has ``margin`` more rows of the same height above and below. The warped row r of
    column k for (rho, alpha) (index ``r_index * n_alpha + a``) is ``(1 - frac) * stored[low] +
    frac * stored[low + 1]`` (rows of the stored image), clamped to its first and last row.
    """
    e = np.asarray(elevations)
    step = e[0] - e[1] if e.size > 1 else 1.0
    phi = TWO_PI * np.arange(n_columns) / n_columns
    alpha = TWO_PI * np.arange(n_alpha) / n_alpha
    r = np.asarray(rho)[:, None, None]
    distance = landmark_distance(r, phi[None, None, :] - alpha[None, :, None])  # (rho, a, k)
    source = np.arctan(np.tan(e) * distance[..., None])  # (rho, a, k, rows)
    n_stored = e.size + 2 * margin
    position = np.clip(margin + (e[0] - source) / step, 0.0, n_stored - 1.0)
    low = np.minimum(np.floor(position).astype(np.intp), max(n_stored - 2, 0))
    shape = (len(rho) * n_alpha, n_columns, e.size)
    return low.reshape(shape), (position - low).reshape(shape)


def spectrum_sums(warped: ComplexArray, band: ComplexArray) -> ComplexArray:
    """``sum over rows r of warped[:, r] * conj(band[r])``, shape (h, f), from the spectra of
    the warped goals (h, rows, f) and of the current band (rows, f): each product as ``(wr br
    + wi bi) + (wi br - wr bi) i``, summed from row 0 on (the reference of
    :func:`homebench.methods.warping_2d.kernels.spectrum_sums`)."""
    wr, wi, br, bi = warped.real, warped.imag, band.real, band.imag
    real = wr[:, 0] * br[0] + wi[:, 0] * bi[0]
    imag = wi[:, 0] * br[0] - wr[:, 0] * bi[0]
    for r in range(1, band.shape[0]):
        real += wr[:, r] * br[r] + wi[:, r] * bi[r]
        imag += wi[:, r] * br[r] - wr[:, r] * bi[r]
    out = np.empty(real.shape, dtype=np.complex128)
    out.real, out.imag = real, imag
    return out


@dataclass(frozen=True)
class GoalPart:
    """What a search needs of the goal alone: ``spectrum`` (n_rho * n_alpha, n_rows, n // 2 +
    1), the rfft of each warped goal's rows, and ``energy`` (n_rho * n_alpha,), each warped
    goal's sum of squares."""

    spectrum: ComplexArray
    energy: FloatArray


def _kernels() -> ModuleType:
    """The compiled kernels, imported by their first use: importing this module (as the
    command line does for every method) does not import numba."""
    from homebench.methods.warping_2d import kernels

    return kernels


@register
@documented
@dataclass(frozen=True)
class Warping2D:
    """2D-warping (Möller 2009): the goal band warped in azimuth and scaled vertically per
    column for every (rho, alpha, psi) under the equal-distance assumption."""

    name: ClassVar[str] = "warping-2d"
    image_kind: ClassVar[ImageKind] = "unfolded"
    preload_modules: ClassVar[tuple[str, ...]] = (
        "homebench.methods.warping_2d.kernels",
        "homebench.methods.warping_2d.plane_kernels",
        "homebench.methods.jit_setup",
    )

    n_columns: int = same_as(MinWarping, "n_columns")
    n_rows: int = param(
        16,
        "Rows of the band compared (scheme image: margin rows for the vertical scaling come on "
        "top).",
        reading="the paper compares the unfolded image's rows around the horizon at its own "
        "resolution; min-warping's band (the same paper), 16 rows of 1.9 deg",
    )
    band_bottom_deg: float = same_as(MinWarping, "band_bottom_deg")
    band_top_deg: float = same_as(MinWarping, "band_top_deg")
    n_rho: int = param(
        20,
        "Search steps of rho = d / r from 0 to rho_max.",
        reading="the paper's rho grid was out of reach; 1-D warping's (Franz et al. 1998, Table "
        "1: 20 steps up to 0.95), which 2D-warping extends",
    )
    rho_max: float | None = param(
        None,
        "Largest rho searched (as n_rho); None: the scheme's, 0.95 with 'image' (which needs "
        "rho_max < 1), 1.0 with 'scale-planes' (which allows rho_max <= 1).",
        reading="the image scheme's is 1-D warping's (Franz et al. 1998, Table 1: 20 steps up "
        "to 0.95); the scale-plane scheme's is Möller's SIMD code's (20 steps from 0 to 1)",
    )
    scheme: Scheme = param(
        "image",
        "How a hypothesis is compared with the current view: 'image' warps the goal band "
        "(columns moved and scaled vertically) and compares it pixel by pixel; 'scale-planes' "
        "looks each goal column up in min-warping's scale-plane stack (current column and "
        "vertical scale quantised, min-warping's column distance, double and fine search), as "
        "Möller's SIMD code runs 2D-warping (homebench.methods.warping_2d.planes).",
        paper="Möller (2009) warps the two-dimensional image itself and compares it with the "
        "current image; the scale-plane scheme is his later implementation's (Möller, "
        "Krzykawski & Gerstmayr 2010), offered to compare with that code",
    )
    columns_per_step: int = same_as(MinWarping, "columns_per_step", _PLANES_ONLY)
    n_scales: int = same_as(MinWarping, "n_scales", _PLANES_ONLY)
    max_scale: float = same_as(MinWarping, "max_scale", _PLANES_ONLY)
    distance: ColumnDistance = same_as(MinWarping, "distance", _PLANES_ONLY)
    edge_filter: bool = same_as(MinWarping, "edge_filter", _PLANES_ONLY)
    double_search: bool = same_as(MinWarping, "double_search", _PLANES_ONLY)
    fine_search: bool = same_as(MinWarping, "fine_search", _PLANES_ONLY)

    # The goal's part of the search, by the goal features' bytes: the currents of one goal
    # share it. Not a parameter.
    _goals: dict[bytes, GoalPart] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )
    # The scale-plane scheme's search (scheme "scale-planes"), made from these parameters.
    _planes: ScalePlaneWarping2D | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_fields(self)
        if self.n_columns < 4 or self.n_rows < 1:
            raise ConfigError("warping-2d: need n_columns >= 4 and n_rows >= 1")
        if not -90.0 < self.band_bottom_deg < 0.0 < self.band_top_deg < 90.0:
            raise ConfigError("warping-2d: the band must contain the horizon (bottom < 0 < top)")
        rho = self.largest_rho
        below_one = rho <= 1.0 if self.scheme == "scale-planes" else rho < 1.0
        if self.n_rho < 2 or not (rho > 0.0 and below_one):
            raise ConfigError(
                "warping-2d: need n_rho >= 2 and 0 < rho_max < 1 (<= 1 with scheme 'scale-planes')"
            )
        if self.scheme == "image":
            changed = [n for n in SCALE_PLANE_PARAMETERS if getattr(self, n) != _min_warping(n)]
            if changed:
                raise ConfigError(
                    f"warping-2d: {', '.join(changed)}: only with scheme 'scale-planes'"
                )
            return
        shared = ("n_columns", "n_rows", "band_bottom_deg", "band_top_deg")
        planes = ScalePlaneWarping2D(
            **{name: getattr(self, name) for name in shared + SCALE_PLANE_PARAMETERS},
            rho=self.rho,
        )
        object.__setattr__(self, "_planes", planes)

    @property
    def largest_rho(self) -> float:
        """rho_max, or the scheme's when it is None."""
        return SCHEME_RHO[self.scheme] if self.rho_max is None else self.rho_max

    @property
    def rho(self) -> tuple[float, ...]:
        """Searched rho values: 0 .. largest_rho in n_rho steps."""
        return rho_grid(self.largest_rho, self.n_rho)

    @property
    def row_step(self) -> float:
        """Elevation per band row, radians."""
        return math.radians(self.band_top_deg - self.band_bottom_deg) / self.n_rows

    @property
    def elevations(self) -> tuple[float, ...]:
        """Centres of the band's rows (radians, top first)."""
        top = math.radians(self.band_top_deg)
        return tuple((top - (np.arange(self.n_rows) + 0.5) * self.row_step).tolist())

    def margin(self, geometry: PanoramaGeometry) -> int:
        """Rows stored above and below the band: enough for the smallest scale 1 / (1 +
        rho_max), as many as the panorama holds."""
        top, bottom = math.radians(self.band_top_deg), math.radians(self.band_bottom_deg)
        reach = max(math.tan(top), -math.tan(bottom)) * (1.0 + self.largest_rho)
        wanted = math.ceil((math.atan(reach) - min(top, -bottom)) / self.row_step - 1e-9)
        room = min(geometry.elevation_top - top, bottom - geometry.elevation_bottom)
        return max(0, min(wanted, math.floor(room / self.row_step + 1e-9)))

    def describe(self, view: View) -> FloatArray:
        """The band with its margins: (n_rows + 2 * margin, n_columns) grey levels, canonical
        columns, top row first."""
        if not isinstance(view.geometry, PanoramaGeometry):
            raise ConfigError("warping-2d: needs an unfolded panorama, got a raw image")
        if self._planes is not None:
            return self._planes.describe(view)
        m = self.margin(view.geometry)
        top = math.radians(self.band_top_deg) + m * self.row_step
        bottom = math.radians(self.band_bottom_deg) - m * self.row_step
        return horizon_band(
            view.image, view.geometry, bottom, top, self.n_rows + 2 * m, self.n_columns
        )

    def warped_goals(self, goal: FloatArray, engine: Engine = "numpy") -> FloatArray:
        """The goal band warped for every (rho, alpha): shape (n_rho * n_alpha, n_rows,
        n_columns), row ``r * n_columns + a`` for (rho[r], alpha = 2*pi*a/n_columns), by numpy
        or the compiled kernel (the same numbers)."""
        n = self.n_columns
        margin = (goal.shape[0] - self.n_rows) // 2
        low, frac = warp_tables(n, self.rho, n)
        rows, weight = row_tables(n, self.rho, n, self.elevations, margin)
        if engine == "numba":
            out = np.empty((low.shape[0], self.n_rows, n))
            _kernels().warp_goal(goal, low, frac, rows, weight, out)
            return out
        columns = (1.0 - frac[:, None, :]) * goal[:, low].transpose(1, 0, 2)
        columns += frac[:, None, :] * goal[:, (low + 1) % n].transpose(1, 0, 2)
        columns = columns.transpose(0, 2, 1)  # (rho * alpha, k, stored rows)
        upper = np.take_along_axis(columns, rows, axis=2)
        lower = np.take_along_axis(columns, np.minimum(rows + 1, goal.shape[0] - 1), axis=2)
        warped = ((1.0 - weight) * upper + weight * lower).transpose(0, 2, 1)
        return np.ascontiguousarray(warped)

    def goal_part(self, goal: FloatArray, engine: Engine = "numpy") -> GoalPart:
        """The goal's part of the search (by the compiled kernel, kept for the last goals, with
        ``engine="numba"``)."""
        if engine == "numpy":
            return self._goal_part(goal, engine)
        key = goal.tobytes()
        part = self._goals.get(key)  # one look-up: threads may share the method
        if part is None:
            part = self._goal_part(goal, engine)
            if len(self._goals) >= GOAL_CACHE_SIZE:
                self._goals.clear()
            self._goals[key] = part
        return part

    def _goal_part(self, goal: FloatArray, engine: Engine) -> GoalPart:
        warped = self.warped_goals(goal, engine)
        spectrum = np.fft.rfft(warped, axis=-1)
        energy = np.sum(np.square(warped, out=warped), axis=(1, 2))  # squared in place: 24 MB
        return GoalPart(spectrum, energy)

    def costs(self, current: FloatArray, goal: FloatArray, engine: Engine = "numpy") -> FloatArray:
        """Sum of squared differences of every (rho, alpha, psi): shape (n_rho, n_columns,
        n_columns); ``current`` and ``goal`` as :meth:`describe` makes them; by numpy or the
        compiled kernels with the goal's part kept (the same numbers)."""
        n = self.n_columns
        margin = (current.shape[0] - self.n_rows) // 2
        band = current[margin : margin + self.n_rows]
        part = self.goal_part(goal, engine)
        spectrum = np.fft.rfft(band, axis=-1)
        if engine == "numba":
            sums = np.empty((len(part.energy), n // 2 + 1), dtype=np.complex128)
            _kernels().spectrum_sums(part.spectrum, spectrum, sums)
        else:
            sums = spectrum_sums(part.spectrum, spectrum)
        # cross[h, p] = sum_k warped[h, :, k] * band[:, k - p]: predicted current(k) = warped(k + p)
        cross = np.fft.irfft(sums, n=n, axis=-1)
        ssd = np.maximum(np.sum(band**2) + part.energy[:, None] - 2.0 * cross, 0.0)
        return ssd.reshape(self.n_rho, n, n)

    def home(
        self, current: FloatArray, goal: FloatArray, engine: Engine = "numba"
    ) -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (rho, alpha, psi); ``engine``:
        the compiled kernels or the pure-numpy reference (same result)."""
        if self._planes is not None:
            return self._planes.home(current, goal, engine)
        if current.shape != goal.shape or current.shape[1:] != (self.n_columns,):
            raise ValueError(f"warping-2d: features must be bands with {self.n_columns} columns")
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(n_landmarks=self.n_columns, reason="no texture")
        return best_hypothesis(self.costs(current, goal, engine), self.rho, self.n_columns)
