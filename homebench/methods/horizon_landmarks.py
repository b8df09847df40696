"""Landmarks as dark and bright sectors of the horizon, for ALV and the snapshot model.

The horizon signal (n,) (canonical columns: column k looks at azimuth ``2*pi*k/n`` ccw) is
thresholded; every maximal circular run of columns below the threshold is a dark sector, every
run at or above it a bright sector, so dark and bright sectors alternate around the horizon. A
sector's centre is the azimuth midway between its first and last column, its width the number
of its columns times the column step. A signal on one side of the threshold everywhere (a flat
one) has no sectors: there is no edge to locate one by.

Threshold rules (the papers use scenes of black landmarks on white, where any grey level between
the two separates them; natural scenes need a rule per image): the signal's ``mean`` or
``median``.

:class:`LandmarkViews` holds what the two methods share besides: their horizon parameters and
``describe`` (the horizon signal). Both compare bearings in one frame: the papers' external
compass, which a grid database captured at one heading stands for; a config entry's
``compass: visual`` (engine level, :data:`homebench.methods.visual_compass.CompassMode`) turns
the current view back by the visual compass before ``describe``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry, wrap_angle
from homebench.imaging.horizon import horizon_signal
from homebench.methods.base import View
from homebench.methods.param_types import check_fields
from homebench.methods.params import param

FloatArray = NDArray[np.float64]

#: Length below which a home vector of unit-vector sums counts as zero (no direction).
ZERO_VECTOR = 1e-9

ThresholdRule = Literal["mean", "median"]
LandmarkKind = Literal["dark", "bright"]


@dataclass(frozen=True)
class Sectors:
    """Sectors of one horizon: centres (m,) radians in [-pi, pi), widths (m,) radians, and
    dark (m,) bool (True: below the threshold). m = 0 when there are none."""

    centres: FloatArray
    widths: FloatArray
    dark: NDArray[np.bool_]

    def of_kind(self, kind: LandmarkKind) -> Sectors:
        """The dark or the bright sectors only."""
        keep = self.dark if kind == "dark" else ~self.dark
        return Sectors(self.centres[keep], self.widths[keep], self.dark[keep])


def threshold(signal: FloatArray, rule: ThresholdRule) -> float:
    """Grey level separating dark from bright columns by ``rule``."""
    return float(np.median(signal)) if rule == "median" else float(np.mean(signal))


def horizon_sectors(signal: FloatArray, rule: ThresholdRule = "mean") -> Sectors:
    """Dark and bright sectors of a horizon signal (n,), in canonical columns."""
    n = signal.size
    dark = signal < threshold(signal, rule)
    starts = np.flatnonzero(dark != np.roll(dark, 1))  # first column of every run
    if starts.size == 0:
        empty = np.zeros(0)
        return Sectors(empty, empty, np.zeros(0, dtype=bool))
    lengths = np.diff(np.append(starts, starts[0] + n))
    step = TWO_PI / n
    centres = wrap_angle((starts + 0.5 * (lengths - 1)) * step)
    return Sectors(centres, lengths * step, dark[starts])


def vector_direction(vector: FloatArray) -> float | None:
    """Angle of a home vector (2,), or None when it is (numerically) zero."""
    if float(np.hypot(vector[0], vector[1])) <= ZERO_VECTOR:
        return None
    return float(np.arctan2(vector[1], vector[0]))


@dataclass(frozen=True)
class LandmarkViews:
    """What ALV and the snapshot model share: the horizon signal and its sectors.

    A mix-in of parameter fields and feature code for the two method dataclasses."""

    band_half_width_deg: float = param(
        1.0,
        "The horizon signal is the mean of the rows within this many degrees of the horizon.",
        reading="the papers threshold the horizon line of black landmarks on white; a narrow band "
        "(about one row of a 72-row panorama) stays on that line, where the sectors seen from "
        "nearby places differ least",
    )
    n_columns: int | None = param(
        None, "Columns of the horizon signal (Fourier-resampled); None keeps the image's width."
    )
    threshold: ThresholdRule = param(
        "mean",
        "Grey level that separates dark from bright columns: the signal's mean or median.",
        reading="the papers' scenes are black and white, where any level between the two "
        "separates landmarks from background; a per-image rule for grey-level scenes",
    )

    def check_landmark_params(self) -> None:
        """ConfigError (naming the method) for a bad choice, band or column count."""
        check_fields(self)
        name = getattr(self, "name", "landmark method")
        if not 0.0 < self.band_half_width_deg < 90.0:
            raise ConfigError(f"{name}: band_half_width_deg must be in (0, 90)")
        if self.n_columns is not None and self.n_columns < 4:
            raise ConfigError(f"{name}: n_columns must be at least 4")

    def describe(self, view: View) -> FloatArray:
        """The horizon signal (n_columns,) in canonical columns."""
        geometry = view.geometry
        if not isinstance(geometry, PanoramaGeometry):
            raise ConfigError("horizon landmarks: need an unfolded panorama, got a raw image")
        n = geometry.width if self.n_columns is None else self.n_columns
        half = np.radians(self.band_half_width_deg)
        return horizon_signal(view.image, geometry, half, n)

    def sectors(self, signal: FloatArray) -> Sectors:
        """Sectors of a horizon signal (n,) by this method's threshold rule."""
        return horizon_sectors(signal, self.threshold)
