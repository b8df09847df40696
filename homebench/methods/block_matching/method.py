"""Vardy and Möller's (2005) optical-flow homing by block matching.

Vardy, A. and Möller, R. (2005). Biologically plausible visual homing methods based on optical
flow techniques. Connection Science 17(1-2), 47-89.

Model: with the two views aligned (an external compass, or a database captured at one
heading), a translation from the goal G to the current place C moves every landmark in the
image away from the direction of the movement and towards the opposite direction, the home
direction: the flow from the goal image to the current image contracts at the home direction
beta. A landmark on the horizon seen at azimuth ``theta`` from C is seen from G displaced by
``delta`` with ``sign(delta) = sign(sin(theta - beta))`` whatever its distance: each flow vector
says on which side of its azimuth the home direction lies. Each one is mapped to the unit vector
perpendicular to its azimuth, turned towards that side, ``sign(delta) * (sin theta, -cos
theta)``, and the direction of their sum is the home direction (the signs are symmetric about
beta, so the sum is exact up to the block sampling; no search for the focus of contraction).
Reading: the paper turns flow vectors into home vectors and sums them; the exact mapping was out
of reach, this one is the distance-free rule the flow geometry gives (Vardy's later homing code
likewise sums one unit vector per correspondence).

Flow: blocks of the current band (``block_size`` x ``block_size`` pixels, centred on the horizon
row, one every ``block_step`` columns) are compared by their sum of squared differences with
the goal band at every displacement within ``search_radius`` columns and ``vertical_radius``
rows (panoramas wrap in azimuth); the horizontal displacement of the best match is the flow
vector at the block's azimuth. Ties go to the smallest displacement (zero first), so an
unchanged block gives no vector. The search is compiled
(:mod:`~homebench.methods.block_matching.kernels`, 0.6 ms a pair at the defaults, bit for bit
numpy's 18 ms loop over the displacements, which the tests keep as its reference).

Alignment: the paper's views are aligned, and so are a grid database's; a config entry's
``compass: visual`` (engine level, any method,
:data:`homebench.methods.image_difference.visual_compass
.CompassMode`) turns a current view back by the visual compass first.

Readings and options (see the parameters): resolution, block size, block spacing and search
radii; unit vectors (not weighted by the displacement). No flow vector at all gives
``angle=None``; a texture-less band gives :meth:`HomingEstimate.none`.

Paper look-up (issue 14): the paper's first page was reached (vdocument.in, "Biologically
plausible visual homing methods based on optical flow techniques": five flow techniques on
image collections of three indoor environments; block matching and two simpler variants home
robustly "despite the simplicity of the matched features", and low-frequency features
suffice), but not its method section: the block size, spacing and search radii are not in
reach here. Chosen as Vardy's homing code has them (options ``block_size``, ``block_step``,
``search_radius``, ``vertical_radius``), to be checked against the paper.

Validation (tests/test_validation_block_matching.py), on the paper's scene, aligned views, and
its headline that homing survives many wrong correspondences: rendered panoramas of a round
arena with the goal at its centre, 36 places 0.3-0.9 m away, give AHC 0.9998 (at most 2.7
deg); with a quarter of the goal's horizon replaced by noise, 17 % of the flow vectors point
the wrong way, and AHC is still 0.98.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View, is_flat
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

#: The largest ``block_size``: the compiled search sums a block's rows as numpy sums rows of up to
#: 128 values (:mod:`~homebench.methods.block_matching.kernels`).
LARGEST_BLOCK = 127


def displacements(search_radius: int, vertical_radius: int) -> IntArray:
    """Candidate (dy, dx) displacements, shape (n, 2), smallest |dx| then |dy| first (so
    ``argmin`` breaks ties towards no displacement)."""
    pairs = [
        (dy, dx)
        for dx in range(-search_radius, search_radius + 1)
        for dy in range(-vertical_radius, vertical_radius + 1)
    ]
    pairs.sort(key=lambda p: (abs(p[1]), abs(p[0]), p[1], p[0]))
    return np.array(pairs, dtype=np.intp)


def block_flow(
    current: FloatArray,
    goal: FloatArray,
    block_size: int,
    centres: IntArray,
    candidates: IntArray,
) -> IntArray:
    """Horizontal displacement (goal column - current column) of the best match of each block.

    ``current``, ``goal``: bands (block_size + 2 * vertical_radius, n), the blocks on the middle
    rows of ``current``; ``centres``: block centre columns (m,); ``candidates``: (dy, dx) pairs
    as :func:`displacements` orders them (the first of equal costs wins). Returns (m,) whole
    columns.
    """
    bands = (np.ascontiguousarray(band, dtype=np.float64) for band in (current, goal))
    indices = (np.ascontiguousarray(v, dtype=np.intp) for v in (centres, candidates))
    return _kernels().block_flow(*bands, block_size, *indices)


def _kernels() -> ModuleType:
    """The compiled search, imported by its first use: importing this module (as the command
    line does for every method) does not import numba."""
    from homebench.methods.block_matching import kernels

    return kernels


def flow_home_vector(azimuths: FloatArray, flow: FloatArray) -> FloatArray:
    """Sum of the unit vectors ``sign(flow) * (sin theta, -cos theta)`` (shape (2,)): each flow
    vector (goal minus current azimuth) at azimuth theta points to the side of the home
    direction; zero flow adds nothing."""
    s = np.sign(flow)
    return np.array([np.sum(s * np.sin(azimuths)), np.sum(-s * np.cos(azimuths))])


@register
@documented
@dataclass(frozen=True)
class BlockMatching:
    """Optical-flow homing by block matching (Vardy and Möller 2005): horizontal flow of
    horizon blocks, each mapped to a vector towards the side of the home direction."""

    name: ClassVar[str] = "block-matching"
    image_kind: ClassVar[ImageKind] = "unfolded"
    preload_modules: ClassVar[tuple[str, ...]] = (
        "homebench.methods.block_matching.kernels",
        "homebench.methods.jit_setup",
    )

    n_columns: int = param(
        192,
        "Columns of the band (square pixels: rows are as tall as columns are wide).",
        reading="the paper works on low-resolution unfolded panoramas of about 200 columns; 192 "
        "columns (1.875 deg per pixel)",
    )
    block_size: int = param(
        7,
        f"Block width and height in pixels (odd, at most {LARGEST_BLOCK}).",
        reading="not in reach in the paper's text; 7 x 7 as Vardy's block-matching homing code "
        "(block radius 3)",
    )
    block_step: int = param(
        2,
        "Columns between block centres along the horizon.",
        reading="as Vardy's block-matching homing code (a block every 2 pixels)",
    )
    search_radius: int = param(
        30,
        "Largest horizontal displacement searched, columns.",
        reading="as Vardy's block-matching homing code (30 pixels, 56 deg here)",
    )
    vertical_radius: int = param(
        3,
        "Largest vertical displacement searched, rows (only the horizontal flow is used).",
        reading="Vardy's code searches as far vertically as horizontally within the image; a "
        "band around the horizon holds a few rows, and horizon blocks move little vertically",
    )

    def __post_init__(self) -> None:
        check_fields(self)
        if not 1 <= self.block_size <= LARGEST_BLOCK or self.block_size % 2 == 0:
            raise ConfigError(f"block-matching: block_size must be odd, from 1 to {LARGEST_BLOCK}")
        if self.block_step < 1 or self.vertical_radius < 0:
            raise ConfigError("block-matching: need block_step >= 1 and vertical_radius >= 0")
        if not 1 <= self.search_radius < self.n_columns // 2:
            raise ConfigError("block-matching: search_radius must be in [1, n_columns / 2)")

    @property
    def n_rows(self) -> int:
        """Rows of the band: a block and the vertical search above and below it."""
        return self.block_size + 2 * self.vertical_radius

    def describe(self, view: View) -> FloatArray:
        """The band (n_rows, n_columns): grey levels centred on the horizon, canonical
        columns."""
        if not isinstance(view.geometry, PanoramaGeometry):
            raise ConfigError("block-matching: needs an unfolded panorama, got a raw image")
        half = 0.5 * self.n_rows * TWO_PI / self.n_columns
        return horizon_band(view.image, view.geometry, -half, half, self.n_rows, self.n_columns)

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction: the direction of the summed flow vectors (current robot frame);
        the features are bands (n_rows, n_columns)."""
        if current.shape != goal.shape:
            raise ValueError("block-matching: features need bands of one shape")
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(reason="no texture")
        centres = np.arange(0, self.n_columns, self.block_step)
        candidates = displacements(self.search_radius, self.vertical_radius)
        flow = block_flow(current, goal, self.block_size, centres, candidates)
        azimuths = TWO_PI * centres / self.n_columns
        x, y = flow_home_vector(azimuths, flow.astype(np.float64))
        moving = int(np.count_nonzero(flow))
        diagnostics = {"flow_columns": flow.tolist()}
        if moving == 0 or math.hypot(x, y) <= 1e-9 * moving:
            return HomingEstimate(None, n_landmarks=moving, diagnostics=diagnostics)
        return HomingEstimate(
            angle=math.atan2(y, x),
            n_landmarks=moving,
            score=math.hypot(x, y) / moving,
            diagnostics=diagnostics,
        )
