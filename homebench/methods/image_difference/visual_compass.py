"""Visual compass: the heading change at the minimum of the rotational image difference function.

Model (Zeil, Hofmann and Chahl 2003, J. Opt. Soc. Am. A 20(3), 450-469; Labrosse 2006, J. Field
Robotics 23(10), 913-931): the current panorama is rotated in azimuth column by column and
compared with the goal panorama; the root-mean-square pixel difference of each rotation is the
rotational image difference function (RIDF). It is smallest at the rotation that undoes the
heading change between the two views, also away from the goal, where the images differ by more
than a rotation (the compass's "catchment"). The method gives no home direction.

Convention: both images in canonical columns (column k looks at azimuth ``2*pi*k/n`` ccw, see
:mod:`homebench.imaging.horizon`). A robot turned ccw by ``psi`` sees at azimuth ``a`` what the
goal saw at ``a + psi``: ``current[k] = goal[k + s]`` with ``s = psi * n / (2*pi)``, so the
current image rolled by ``s`` columns (``np.roll(current, s, axis=-1)``) matches the goal and
the RIDF at shift ``s`` is ``sqrt(mean((roll(current, s) - goal)**2))``; the estimated rotation
is ``s_min * 2*pi/n``, wrapped to [-pi, pi).

:func:`compass_rotation` is the one compass step of this package. The engine applies it to any
method whose config entry says ``compass: visual`` (see :data:`CompassMode`): it turns the
current view back by the estimate (:func:`compass_turn`) before the method describes it, and
:func:`in_current_frame` turns the method's answer into the current robot frame.

Readings and options (see the parameters): the image region (the whole unfolded image, both
papers, or an elevation band); the resolution (the image's own width); sub-column refinement by
a parabola through the minimum and its neighbours (an option; the papers take the best whole
rotation). A texture-less image gives :meth:`HomingEstimate.none`.

Pre-smoothing (``blur_deg``, also MFDID's and DID's): a Gaussian low-pass of the compared
image, off by default (the papers' readings could not be checked here: see the parameter).

Validation (tests/test_validation_visual_compass.py), on the papers' scene, views turned on the
spot and near the snapshot's place (rendered panoramas of a round arena, 288 columns): turns by
whole columns are found exactly; any other turn within half a column (measured 0.48), within
0.01 column with the parabolic refinement (measured 0.002); views 0.15-0.3 m from the goal,
turned by 40 deg, within 1.4 deg.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry, wrap_angle
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, ImageKind, View, is_flat
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]

#: A method entry's ``compass`` (engine level, any method): ``none`` (the views as stored: a
#: grid database captured at one heading is the papers' external compass), ``visual`` (the
#: current view turned back by this compass's estimate) or ``truth`` (turned back by the true
#: heading change, to whole columns: an ideal compass, to tell compass from homing errors).
CompassMode = Literal["none", "visual", "truth"]


def ridf(current: ArrayLike, goal: ArrayLike) -> FloatArray:
    """Rotational image difference function, shape (n,): RMS difference of
    ``roll(current, s, axis=-1)`` and ``goal`` for every column shift ``s = 0 .. n-1``.

    ``current``, ``goal``: images of equal shape (n,) or (rows, n), canonical columns. One FFT
    cross-correlation: ``sum (c_s - g)**2 = sum c**2 + sum g**2 - 2 sum_k g[k] c[k - s]``.
    """
    c = np.atleast_2d(np.asarray(current, dtype=np.float64))
    g = np.atleast_2d(np.asarray(goal, dtype=np.float64))
    if c.shape != g.shape:
        raise ValueError(f"compass: images differ in shape, {c.shape} and {g.shape}")
    n = c.shape[-1]
    cross = np.fft.irfft(np.fft.rfft(g, axis=-1) * np.conj(np.fft.rfft(c, axis=-1)), n=n)
    ssd = np.sum(c**2) + np.sum(g**2) - 2.0 * np.sum(cross, axis=0)
    return np.sqrt(np.maximum(ssd, 0.0) / c.size)


def minimum_shift(profile: FloatArray, interpolate: bool = False) -> float:
    """Column shift (fractional when ``interpolate``) of the minimum of a periodic ``profile``.

    The whole-column minimum (the first of ties); with ``interpolate``, the vertex of the
    parabola through the squared profile there and at its two neighbours (the mean squared
    difference is smooth at its minimum, where the RMS has a kink; no change when the parabola
    is flat).
    """
    s = int(np.argmin(profile))
    if not interpolate:
        return float(s)
    n = profile.size
    left, centre, right = profile[[(s - 1) % n, s, (s + 1) % n]] ** 2
    curvature = left - 2.0 * centre + right
    return float(s + 0.5 * (left - right) / curvature) if curvature > 0 else float(s)


def compass_rotation(
    current_image: ArrayLike, goal_image: ArrayLike, *, interpolate: bool = False
) -> float:
    """Heading change goal -> current (radians, ccw, in [-pi, pi)) at the RIDF minimum.

    Images: equal shapes (n,) or (rows, n), canonical columns (:func:`compass_image` makes
    them from views). Texture-less images have a flat RIDF and give 0.
    """
    profile = ridf(current_image, goal_image)
    return float(wrap_angle(minimum_shift(profile, interpolate) * TWO_PI / profile.size))


def check_band(name: str, band: tuple[float, float] | None) -> None:
    """ConfigError unless ``band`` is None or (bottom, top) degrees with bottom < top."""
    if band is not None and (len(band) != 2 or not band[0] < band[1]):
        raise ConfigError(f"{name}: elevation_range_deg must be (bottom, top) with bottom < top")


def whole_columns(angle: float, columns: int) -> float:
    """``angle`` (radians) rounded to a whole number of ``columns``-column steps, in [-pi, pi)."""
    step = TWO_PI / columns
    return float(wrap_angle(round(angle / step) * step))


def in_current_frame(estimate: HomingEstimate, turn: float) -> HomingEstimate:
    """An estimate made on the current view turned back by ``turn`` (radians, ccw: the view
    a robot turned by ``-turn`` sees), in the current robot frame: the direction minus
    ``turn``, the heading change plus ``turn`` (``turn`` alone when the method gives none)."""
    angle = None if estimate.angle is None else float(wrap_angle(estimate.angle - turn))
    rotation = float(wrap_angle(turn + (estimate.rotation or 0.0)))
    return replace(estimate, angle=angle, rotation=rotation)


def low_pass(
    image: FloatArray, blur_deg: float | None, row_step: float, column_step: float
) -> FloatArray:
    """``image`` (rows, n) blurred by an isotropic Gaussian of standard deviation ``blur_deg``
    degrees of view angle (``row_step``, ``column_step``: radians per row and column); azimuth
    wraps round, rows replicate at the top and bottom. ``None`` or 0: ``image`` unchanged."""
    if not blur_deg:
        return image
    from scipy.ndimage import gaussian_filter  # imported where needed: a method's first use

    sigma = np.radians(blur_deg)
    return gaussian_filter(image, (sigma / row_step, sigma / column_step), mode=("nearest", "wrap"))


def compass_image(
    view: View,
    elevation_range_deg: tuple[float, float] | None = None,
    blur_deg: float | None = None,
) -> FloatArray:
    """The image the compass compares, (rows, width) grey levels in canonical columns.

    ``elevation_range_deg``: (bottom, top) of a band in degrees, or None for the whole unfolded
    image (every row as it is). ``blur_deg``: the Gaussian low-pass of :func:`low_pass` applied
    to it (None: none)."""
    geometry = view.geometry
    if not isinstance(geometry, PanoramaGeometry):
        raise ConfigError("visual compass: needs an unfolded panorama, got a raw image")
    if elevation_range_deg is None:
        bottom, top = geometry.elevation_bottom, geometry.elevation_top
        n_rows = geometry.height
    else:
        bottom, top = np.radians(elevation_range_deg)
        n_rows = max(1, round((top - bottom) / geometry.row_step))
    image = horizon_band(view.image, geometry, bottom, top, n_rows, geometry.width)
    return low_pass(image, blur_deg, (top - bottom) / n_rows, geometry.column_step)


def compass_turn(current: View, goal: View) -> float:
    """Heading change goal -> current (radians, whole columns) of two unfolded views, their
    whole images compared (the compass step of ``compass: visual``)."""
    return compass_rotation(compass_image(current), compass_image(goal))


@dataclass(frozen=True)
class WholeImageViews:
    """Mix-in of the methods that compare whole unfolded images (or an elevation band) in
    canonical columns (visual compass, MFDID, DID): their ``elevation_range_deg`` parameter,
    its check and ``describe``."""

    elevation_range_deg: tuple[float, float] | None = param(
        None,
        "Elevation band (bottom, top) in degrees of the compared images; None: the whole "
        "unfolded image.",
        reading="the papers (Zeil et al. 2003, Labrosse 2006, Möller and Vardy 2006) compare "
        "whole panoramas; a band (the horizon region, say) leaves out the floor and sky a "
        "database may show differently",
    )
    blur_deg: float | None = param(
        None,
        "Pre-smoothing: standard deviation (degrees of view angle) of a Gaussian low-pass of "
        "the compared image (azimuth wraps round); None: the image as the database holds it.",
        reading="unverified: the texts of Zeil et al. (2003), Labrosse (2006) and Möller and "
        "Vardy (2006) were out of reach here, so whether and at what scale they low-pass is "
        "unchecked and the default stays no smoothing. Vardy's MFDID code reads pre-processed "
        "databases whose file names ('_bw0.19') suggest a Butterworth low-pass, cut-off 0.19; "
        "a Gaussian is homebench's stand-in. Smoothing widens the range where the image "
        "changes to first order (poster room, seed 0: MFDID's AHC 0.354 -> 0.551 at 10 deg, "
        "DID's 0.428 -> 0.587)",
    )

    def __post_init__(self) -> None:
        check_fields(self)
        name = getattr(self, "name", "method")
        check_band(name, self.elevation_range_deg)
        if self.blur_deg is not None and self.blur_deg < 0:
            raise ConfigError(f"{name}: blur_deg must be >= 0 or null")

    def describe(self, view: View) -> FloatArray:
        """The compared image (rows, width): grey levels, canonical columns, low-passed by
        ``blur_deg``."""
        return compass_image(view, self.elevation_range_deg, self.blur_deg)


@register
@documented
@dataclass(frozen=True)
class VisualCompass(WholeImageViews):
    """Visual compass (Zeil et al. 2003; Labrosse 2006): heading change at the RIDF minimum."""

    name: ClassVar[str] = "visual-compass"
    image_kind: ClassVar[ImageKind] = "unfolded"
    gives_direction: ClassVar[bool] = False

    interpolate: bool = param(
        False,
        "Refine the minimum to a fraction of a column by a parabola through the best shift and "
        "its neighbours.",
        paper="Zeil et al. and Labrosse take the best whole rotation step of the RIDF",
    )

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Rotation only (``angle`` is None): the heading change at the RIDF minimum."""
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(reason="no texture")
        profile = ridf(current, goal)
        shift = minimum_shift(profile, self.interpolate)
        return HomingEstimate(
            angle=None,
            rotation=float(wrap_angle(shift * TWO_PI / profile.size)),
            n_landmarks=int(current.size),
            score=float(np.min(profile)),
            diagnostics={"shift": shift},
        )
