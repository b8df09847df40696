"""Landmarks as dark and bright sectors of the horizon, for ALV and the snapshot model.

The horizon signal (n,) (canonical columns: column k looks at azimuth ``2*pi*k/n`` ccw) is
thresholded; every maximal circular run of columns below the threshold is a dark sector, every
run at or above it a bright sector, so dark and bright sectors alternate around the horizon. A
sector's centre is the azimuth midway between its first and last column, its width the number
of its columns times the column step. A signal on one side of the threshold everywhere (a flat
one) has no sectors: there is no edge to locate one by.

The papers' scenes are black cylinders on a bright background (Cartwright and Collett 1983;
Lambrinos et al. 2000; Möller 2001): two populations of grey levels, which any level between
them separates. The segmentation takes three steps, each a parameter shared by both methods:

1. ``blur_deg``: a Gaussian low-pass of the signal in azimuth (a photoreceptor's acceptance
   angle); 0 (the default) keeps the signal as the band gives it.
2. ``threshold``: the rule that picks the grey level per image: ``otsu`` (the default: the
   level that best separates two classes, Otsu 1979: the papers' two populations), the
   signal's ``mean`` or its ``median``. The mean (homebench's first reading) fails in the
   papers' own kind of scene once the wall is lit unevenly: a few narrow dark landmarks pull
   the mean only a little below the wall's level, and every dimmer stretch of wall falls below
   it (tests/test_validation_alv.py).
3. ``min_width_deg``: runs narrower than this are merged into their neighbours (the narrowest
   first), so that a few columns of texture or noise are not landmarks; 0 (the default): none.

The defaults are the segmentation that finds exactly the ground-truth landmarks (a generated
world's objects, ``render: landmarks``) in the papers' scene (style ``arena``); in textured
places no setting of the three finds the objects, which need not be darker than what is
behind them (docs/measured/baselines.md: the baselines and the ground-truth-landmark control).

:class:`LandmarkViews` holds what the two methods share besides: their horizon parameters and
``describe`` (the horizon signal). Both compare bearings in one frame: the papers' external
compass, which a grid database captured at one heading stands for; a config entry's
``compass: visual`` (engine level,
:data:`homebench.methods.image_difference.visual_compass.CompassMode`) turns
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
from homebench.methods.image_difference.visual_compass import low_pass
from homebench.methods.param_types import check_fields
from homebench.methods.params import param

FloatArray = NDArray[np.float64]

#: Length below which a home vector of unit-vector sums counts as zero (no direction).
ZERO_VECTOR = 1e-9

ThresholdRule = Literal["otsu", "mean", "median"]
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


def otsu_threshold(signal: FloatArray) -> float:
    """Otsu's threshold of ``signal`` (n,): the grey level midway between the two neighbouring
    sorted values whose split into a dark and a bright class has the largest between-class
    variance (exact on the values, no histogram bins); a flat signal gives its value."""
    values = np.sort(np.asarray(signal, dtype=np.float64))
    n = values.size
    below = np.arange(1, n)  # values in the dark class, per split
    total = np.cumsum(values)
    dark_mean = total[:-1] / below
    bright_mean = (total[-1] - total[:-1]) / (n - below)
    between = below * (n - below) * (dark_mean - bright_mean) ** 2
    between[values[1:] == values[:-1]] = -1.0  # no split between equal values
    if between.size == 0 or between.max() < 0:
        return float(values[0])
    split = int(np.argmax(between))
    return float((values[split] + values[split + 1]) / 2)


def threshold(signal: FloatArray, rule: ThresholdRule) -> float:
    """Grey level separating dark from bright columns by ``rule``."""
    if rule == "median":
        return float(np.median(signal))
    if rule == "mean":
        return float(np.mean(signal))
    return otsu_threshold(signal)


def runs(dark: NDArray[np.bool_]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """First columns and lengths (m,) of the maximal circular runs of equal values of ``dark``
    (n,), in column order; m = 0 when all values are equal."""
    starts = np.flatnonzero(dark != np.roll(dark, 1))
    if starts.size == 0:
        return starts, starts.copy()
    return starts, np.diff(np.append(starts, starts[0] + dark.size))


def merge_narrow(dark: NDArray[np.bool_], min_columns: int) -> NDArray[np.bool_]:
    """``dark`` (n,) with every run shorter than ``min_columns`` merged into its neighbours,
    the narrowest run first (its columns take its neighbours' value); a new array."""
    dark = dark.copy()
    while True:
        starts, lengths = runs(dark)
        if starts.size == 0 or lengths.min() >= min_columns:
            return dark
        narrowest = int(np.argmin(lengths))
        columns = (starts[narrowest] + np.arange(lengths[narrowest])) % dark.size
        dark[columns] = ~dark[columns]


def horizon_sectors(
    signal: FloatArray, rule: ThresholdRule = "otsu", min_width: float = 0.0
) -> Sectors:
    """Dark and bright sectors of a horizon signal (n,), in canonical columns: thresholded by
    ``rule``, runs narrower than ``min_width`` (radians) merged into their neighbours."""
    n = signal.size
    step = TWO_PI / n
    dark = signal < threshold(signal, rule)
    if min_width > 0.0:
        dark = merge_narrow(dark, int(np.ceil(min_width / step - 1e-9)))
    starts, lengths = runs(dark)
    if starts.size == 0:
        empty = np.zeros(0)
        return Sectors(empty, empty, np.zeros(0, dtype=bool))
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
    blur_deg: float = param(
        0.0,
        "Standard deviation (degrees of azimuth) of a Gaussian low-pass of the horizon signal "
        "before it is thresholded (azimuth wraps round); 0: none.",
        reading="a photoreceptor's acceptance angle; whether the papers smooth could not be "
        "checked (their texts were out of reach). Off: the papers' scene needs none (Otsu alone "
        "finds exactly the cylinders of the arena style), and in the textured styles blur "
        "(1-3 deg) leaves fewer sectors but does not bring their columns closer to the "
        "ground-truth objects' (overlap within 0.01 of none)",
    )
    threshold: ThresholdRule = param(
        "otsu",
        "Grey level that separates dark from bright columns, per image: otsu (the level that "
        "best separates two classes), or the signal's mean or median.",
        reading="the papers' scenes are black cylinders on a bright background, two populations "
        "that any level between them separates; Otsu's two-class threshold is that intent per "
        "image. The mean (the first reading here) fails the papers' own scene once the wall is "
        "lit unevenly: a few narrow landmarks pull it only a little below the wall, and the "
        "dim wall becomes landmarks (arena style: 6.3 dark sectors per view for 4 cylinders)",
    )
    min_width_deg: float = param(
        0.0,
        "Runs of columns narrower than this many degrees are merged into their neighbours "
        "(the narrowest first); 0: every run is a sector.",
        reading="not in the papers as far as could be checked; off by default: 4 deg or more "
        "merges away far cylinders of the arena style, and in the textured styles it only "
        "removes sectors, without matching the ground-truth objects better (the columns' "
        "overlap with the objects' within 0.01 of none)",
    )

    def check_landmark_params(self) -> None:
        """ConfigError (naming the method) for a bad choice, band or column count."""
        check_fields(self)
        name = getattr(self, "name", "landmark method")
        if not 0.0 < self.band_half_width_deg < 90.0:
            raise ConfigError(f"{name}: band_half_width_deg must be in (0, 90)")
        if self.n_columns is not None and self.n_columns < 4:
            raise ConfigError(f"{name}: n_columns must be at least 4")
        if not 0.0 <= self.blur_deg <= 45.0:
            raise ConfigError(f"{name}: blur_deg must be in [0, 45]")
        if not 0.0 <= self.min_width_deg < 180.0:
            raise ConfigError(f"{name}: min_width_deg must be in [0, 180)")

    def describe(self, view: View) -> FloatArray:
        """The horizon signal (n_columns,) in canonical columns, low-passed by ``blur_deg``."""
        geometry = view.geometry
        if not isinstance(geometry, PanoramaGeometry):
            raise ConfigError("horizon landmarks: need an unfolded panorama, got a raw image")
        n = geometry.width if self.n_columns is None else self.n_columns
        half = np.radians(self.band_half_width_deg)
        signal = horizon_signal(view.image, geometry, half, n)
        step = TWO_PI / n
        return low_pass(signal[None, :], self.blur_deg, step, step)[0]

    def sectors(self, signal: FloatArray) -> Sectors:
        """Sectors of a horizon signal (n,) by this method's threshold rule and least width."""
        return horizon_sectors(signal, self.threshold, np.radians(self.min_width_deg))
