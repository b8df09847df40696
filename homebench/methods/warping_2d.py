"""Möller's (2009) 2D-warping: 1-D warping's search on the two-dimensional horizon band.

Möller, R. (2009). Local visual homing by warping of two-dimensional images. Robotics and
Autonomous Systems 57(1), 87-101.

Model: 1-D warping's (see :mod:`homebench.methods.warping`): the robot left the goal in
direction ``alpha`` for ``rho`` landmark distances and turned by ``psi``, all landmarks at one
distance from the goal (the equal-distance assumption). In two dimensions a landmark moves in
azimuth AND changes its distance, so each column of the goal image is also scaled vertically:
a landmark at unit distance from the goal, seen from the current place at (rotated) azimuth
``phi``, lies at distance ``r' = -rho cos(phi - alpha) + sqrt(1 - rho**2 sin**2(phi - alpha))``
there; a point at height ``h`` above the camera is seen under elevation ``atan(h)`` at the
goal and ``atan(h / r')`` at the current place. The predicted current image at (phi, elevation
e) is therefore the goal image at azimuth ``theta = phi - arcsin(rho sin(phi - alpha))`` (1-D
warping's tables, :func:`homebench.methods.warping.warp_tables`) and elevation
``atan(tan(e) * r')``, rotated by psi. The search minimises the image distance over (rho,
alpha, psi) and the home direction is ``beta = alpha - psi + pi`` (current robot frame).

Implementation: each view is described by its band (``n_rows`` rows from ``band_bottom_deg``
to ``band_top_deg``) plus margin rows above and below with the same row height, so the goal can
be sampled at the elevations a shrinking column needs (``r' > 1``: up to
``atan(tan(top) * (1 + rho_max))``; margins are limited to the panorama, and samples beyond
them take the nearest stored row). The warped goal is interpolated bilinearly (columns as in
1-D warping, then rows). Psi runs over whole columns: the distance of every psi is one FFT
cross-correlation per (rho, alpha).

Readings (see the parameters): the band and its resolution are min-warping's (the same paper
introduces both methods), alpha and psi in whole columns of the band; the rho grid is 1-D
warping's (Franz et al. 1998, Table 1); the image distance is the sum of squared differences.
``rho = 0`` carries no direction (every alpha gives the same warp): the estimate then has
``angle=None`` but keeps the rotation. A texture-less band gives :meth:`HomingEstimate.none`.

Paper look-up (issue 14): Möller's (2009) rho grid is not in reach here: the searched public
pages hold no text of the paper (searches for its title and for the warping parameter grid
found unrelated image-warping pages). Chosen as 1-D warping's grid (option ``n_rho``), to be
checked against the paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View
from homebench.methods.min_warping import MinWarping
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param, same_as
from homebench.methods.registry import register
from homebench.methods.warping import best_hypothesis, is_flat, rho_grid, warp_tables

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


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


@register
@documented
@dataclass(frozen=True)
class Warping2D:
    """2D-warping (Möller 2009): the goal band warped in azimuth and scaled vertically per
    column for every (rho, alpha, psi) under the equal-distance assumption."""

    name: ClassVar[str] = "warping-2d"
    image_kind: ClassVar[ImageKind] = "unfolded"

    n_columns: int = same_as(MinWarping, "n_columns")
    n_rows: int = param(
        16,
        "Rows of the band compared (margin rows for the vertical scaling come on top).",
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
    rho_max: float = param(0.95, "Largest rho searched (as n_rho).")

    def __post_init__(self) -> None:
        check_fields(self)
        if self.n_columns < 4 or self.n_rows < 1:
            raise ConfigError("warping-2d: need n_columns >= 4 and n_rows >= 1")
        if not -90.0 < self.band_bottom_deg < 0.0 < self.band_top_deg < 90.0:
            raise ConfigError("warping-2d: the band must contain the horizon (bottom < 0 < top)")
        if self.n_rho < 2 or not 0.0 < self.rho_max < 1.0:
            raise ConfigError("warping-2d: need n_rho >= 2 and 0 < rho_max < 1")

    @property
    def rho(self) -> tuple[float, ...]:
        """Searched rho values: 0 .. rho_max in n_rho steps."""
        return rho_grid(self.rho_max, self.n_rho)

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
        reach = max(math.tan(top), -math.tan(bottom)) * (1.0 + self.rho_max)
        wanted = math.ceil((math.atan(reach) - min(top, -bottom)) / self.row_step - 1e-9)
        room = min(geometry.elevation_top - top, bottom - geometry.elevation_bottom)
        return max(0, min(wanted, math.floor(room / self.row_step + 1e-9)))

    def describe(self, view: View) -> FloatArray:
        """The band with its margins: (n_rows + 2 * margin, n_columns) grey levels, canonical
        columns, top row first."""
        if not isinstance(view.geometry, PanoramaGeometry):
            raise ConfigError("warping-2d: needs an unfolded panorama, got a raw image")
        m = self.margin(view.geometry)
        top = math.radians(self.band_top_deg) + m * self.row_step
        bottom = math.radians(self.band_bottom_deg) - m * self.row_step
        return horizon_band(
            view.image, view.geometry, bottom, top, self.n_rows + 2 * m, self.n_columns
        )

    def warped_goals(self, goal: FloatArray) -> FloatArray:
        """The goal band warped for every (rho, alpha): shape (n_rho * n_alpha, n_rows,
        n_columns), row ``r * n_columns + a`` for (rho[r], alpha = 2*pi*a/n_columns)."""
        n = self.n_columns
        margin = (goal.shape[0] - self.n_rows) // 2
        low, frac = warp_tables(n, self.rho, n)
        columns = (1.0 - frac[:, None, :]) * goal[:, low].transpose(1, 0, 2)
        columns += frac[:, None, :] * goal[:, (low + 1) % n].transpose(1, 0, 2)
        columns = columns.transpose(0, 2, 1)  # (rho * alpha, k, stored rows)
        rows, weight = row_tables(n, self.rho, n, self.elevations, margin)
        upper = np.take_along_axis(columns, rows, axis=2)
        lower = np.take_along_axis(columns, np.minimum(rows + 1, goal.shape[0] - 1), axis=2)
        return ((1.0 - weight) * upper + weight * lower).transpose(0, 2, 1)

    def costs(self, current: FloatArray, goal: FloatArray) -> FloatArray:
        """Sum of squared differences of every (rho, alpha, psi): shape (n_rho, n_columns,
        n_columns); ``current`` and ``goal`` as :meth:`describe` makes them."""
        n = self.n_columns
        margin = (current.shape[0] - self.n_rows) // 2
        band = current[margin : margin + self.n_rows]
        warped = self.warped_goals(goal)
        # cross[h, p] = sum_k warped[h, :, k] * band[:, k - p]: predicted current(k) = warped(k + p)
        spectrum = np.fft.rfft(warped, axis=-1) * np.conj(np.fft.rfft(band, axis=-1))
        cross = np.fft.irfft(spectrum.sum(axis=1), n=n, axis=-1)
        energy = np.sum(warped**2, axis=(1, 2))
        ssd = np.maximum(np.sum(band**2) + energy[:, None] - 2.0 * cross, 0.0)
        return ssd.reshape(self.n_rho, n, n)

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction beta = alpha - psi + pi at the best (rho, alpha, psi)."""
        if current.shape != goal.shape or current.shape[1:] != (self.n_columns,):
            raise ValueError(f"warping-2d: features must be bands with {self.n_columns} columns")
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(n_landmarks=self.n_columns, reason="no texture")
        return best_hypothesis(self.costs(current, goal), self.rho, self.n_columns)
