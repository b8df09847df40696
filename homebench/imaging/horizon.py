"""Horizon band extraction from unfolded panoramas, in the canonical column order.

Every method that works on the horizon region asks this module for it, so that it never has to
know a database's column direction or zero column: the output's column ``k`` of ``n`` always
looks at azimuth ``2*pi*k/n`` (counter-clockwise, 0 = the robot's heading) and its rows are
evenly spaced in elevation, top row first.

Resampling: rows by area averaging (each output row is the overlap-weighted mean of the image
rows it covers, so a wide band is averaged, not aliased); columns by band-limited (Fourier)
interpolation of the periodic signal, which handles a fractional zero column, either direction
and any change of width (down-sampling keeps the frequencies both widths can represent).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.errors import ConfigError
from homebench.geometry import PanoramaGeometry

FloatArray = NDArray[np.float64]


def canonical_columns(
    values: ArrayLike, geometry: PanoramaGeometry, n_columns: int | None = None
) -> FloatArray:
    """Resample the last axis (``geometry.width`` columns) to ``n_columns`` canonical columns.

    ``values``: shape (..., width). Returns float64 of shape (..., n_columns) whose column k
    holds azimuth ``2*pi*k/n_columns`` ccw. A same-width ccw panorama with an integer zero
    column is rolled exactly; anything else is Fourier-resampled.
    """
    a = np.asarray(values, dtype=np.float64)
    width = geometry.width
    if a.shape[-1] != width:
        raise ValueError(f"last axis has {a.shape[-1]} columns, geometry says {width}")
    n = width if n_columns is None else int(n_columns)
    if n < 1:
        raise ValueError(f"n_columns must be positive, got {n}")
    zero = geometry.zero_column
    if geometry.direction == "cw":  # reversed columns are ccw with the mirrored zero column
        a = a[..., ::-1]
        zero = width - 1 - zero
    if n == width and float(zero).is_integer():
        return np.roll(a, -int(zero), axis=-1)
    spectrum = np.fft.rfft(a, axis=-1)
    spectrum *= np.exp(2j * np.pi * np.arange(spectrum.shape[-1]) * zero / width)
    keep = (min(width, n) + 1) // 2  # strictly below both Nyquist frequencies
    out = np.zeros(a.shape[:-1] + (n // 2 + 1,), dtype=np.complex128)
    out[..., :keep] = spectrum[..., :keep]
    return np.fft.irfft(out, n=n, axis=-1) * (n / width)


def band_elevations(bottom: float, top: float, n_rows: int) -> FloatArray:
    """Elevations (radians) of the row centres of an ``n_rows`` band from ``top`` to ``bottom``."""
    step = (top - bottom) / n_rows
    return top - (np.arange(n_rows) + 0.5) * step


def row_weights(geometry: PanoramaGeometry, bottom: float, top: float, n_rows: int) -> FloatArray:
    """Area-averaging matrix (n_rows, height): band row r = weights[r] @ image rows.

    Band ``[bottom, top]`` (radians) must lie within the panorama's elevation range.
    """
    if not bottom < top:
        raise ConfigError(f"horizon band: bottom {bottom} rad must be below top {top} rad")
    if bottom < geometry.elevation_bottom - 1e-9 or top > geometry.elevation_top + 1e-9:
        raise ConfigError(
            f"horizon band [{np.degrees(bottom):.1f}, {np.degrees(top):.1f}] deg lies outside "
            f"the panorama's elevations [{np.degrees(geometry.elevation_bottom):.1f}, "
            f"{np.degrees(geometry.elevation_top):.1f}] deg"
        )
    edges = top - np.arange(n_rows + 1) * (top - bottom) / n_rows  # (n_rows + 1,) descending
    src = geometry.elevation_top - np.arange(geometry.height + 1) * geometry.row_step
    hi = np.minimum(edges[:-1, None], src[None, :-1])
    lo = np.maximum(edges[1:, None], src[None, 1:])
    overlap = np.clip(hi - lo, 0.0, None)
    return overlap / overlap.sum(axis=1, keepdims=True)


def horizon_band(
    image: ArrayLike,
    geometry: PanoramaGeometry,
    bottom: float,
    top: float,
    n_rows: int,
    n_columns: int,
) -> FloatArray:
    """Band image (n_rows, n_columns), grey levels, canonical columns, rows top to bottom.

    ``image``: (height, width) unfolded panorama described by ``geometry``; ``bottom``/``top``:
    elevation range in radians. Only unfolded panoramas have a band (anything else: ConfigError).
    """
    if not isinstance(geometry, PanoramaGeometry):
        raise ConfigError("horizon extraction needs an unfolded panorama, got a raw image")
    rows = row_weights(geometry, bottom, top, n_rows) @ np.asarray(image, dtype=np.float64)
    return canonical_columns(rows, geometry, n_columns)


def horizon_signal(
    image: ArrayLike, geometry: PanoramaGeometry, half_width: float, n_columns: int
) -> FloatArray:
    """1-D horizon (n_columns,): the mean over elevations [-half_width, +half_width] (radians)."""
    return horizon_band(image, geometry, -half_width, half_width, 1, n_columns)[0]
