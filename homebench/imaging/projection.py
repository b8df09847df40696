"""Catadioptric <-> unfolded panorama: precomputed ``cv2.remap`` maps between camera models.

The maps are built only from :mod:`homebench.geometry`'s pixel <-> bearing functions and are
cached per geometry pair (the geometries are frozen dataclasses, hence hashable). Both
directions can supersample: each output pixel is sampled on an ``s x s`` grid of sub-pixel
centres and area-averaged, which suppresses aliasing when the source is finer than the output.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry

Map = NDArray[np.float32]


def _subpixel_centres(n: int, supersample: int) -> NDArray[np.float64]:
    """Coordinates, in output pixels, of the ``supersample`` sub-pixel centres of ``n`` pixels.

    Shape (n * supersample,). Block ``k`` of them averages to pixel centre ``k``.
    """
    return (np.arange(n * supersample) + 0.5) / supersample - 0.5


def _frozen(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    for a in arrays:
        a.setflags(write=False)
    return arrays


def _area_average(image: np.ndarray, supersample: int) -> np.ndarray:
    """Average ``supersample x supersample`` blocks; shape (h / s, w / s)."""
    if supersample == 1:
        return image
    h, w = image.shape[:2]
    return cv2.resize(image, (w // supersample, h // supersample), interpolation=cv2.INTER_AREA)


def _check_supersample(supersample: int) -> None:
    if supersample < 1:
        raise ValueError(f"supersample must be a positive integer, got {supersample}")


@lru_cache(maxsize=16)
def unfold_maps(
    raw_geometry: CatadioptricGeometry, pano_geometry: PanoramaGeometry, supersample: int = 1
) -> tuple[Map, Map]:
    """Raw-image coordinates (u, v) of every panorama sample; each of shape (h*s, w*s), float32."""
    _check_supersample(supersample)
    azimuth = pano_geometry.column_to_azimuth(_subpixel_centres(pano_geometry.width, supersample))
    elevation = pano_geometry.row_to_elevation(_subpixel_centres(pano_geometry.height, supersample))
    u, v = raw_geometry.bearing_to_pixel(azimuth[None, :], elevation[:, None])
    return _frozen(u.astype(np.float32), v.astype(np.float32))  # type: ignore[return-value]


@lru_cache(maxsize=16)
def fold_maps(
    pano_geometry: PanoramaGeometry, raw_geometry: CatadioptricGeometry, supersample: int = 2
) -> tuple[Map, Map, NDArray[np.bool_]]:
    """Panorama coordinates (column, row) of every raw-image sample, and the annulus mask.

    Shapes (H*s, W*s) for a raw image of H x W. Columns are in [0, width) (azimuth wraps);
    the mask is True for samples between the inner and outer radius.
    """
    _check_supersample(supersample)
    us = _subpixel_centres(raw_geometry.width, supersample)[None, :]
    vs = _subpixel_centres(raw_geometry.height, supersample)[:, None]
    azimuth, elevation = raw_geometry.pixel_to_bearing(us, vs)
    column = pano_geometry.azimuth_to_column(azimuth)
    row = np.broadcast_to(pano_geometry.elevation_to_row(elevation), column.shape)
    radius = np.hypot(us - raw_geometry.centre[0], vs - raw_geometry.centre[1])
    mask = (radius >= raw_geometry.inner_radius) & (radius <= raw_geometry.outer_radius)
    return _frozen(column.astype(np.float32), row.astype(np.float32), mask)  # type: ignore[return-value]


def unfold(
    raw: np.ndarray,
    raw_geometry: CatadioptricGeometry,
    pano_geometry: PanoramaGeometry,
    supersample: int = 1,
) -> np.ndarray:
    """Raw catadioptric image (H, W) -> unfolded panorama (height, width), bilinear.

    With ``supersample`` > 1 each panorama pixel averages s x s bilinear samples. Bearings that
    fall outside the raw image read as 0. The dtype is preserved.
    """
    mx, my = unfold_maps(raw_geometry, pano_geometry, supersample)
    out = cv2.remap(raw, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return _area_average(out, supersample)


@lru_cache(maxsize=8)
def tangential_widths(
    pano_geometry: PanoramaGeometry, raw_geometry: CatadioptricGeometry, supersample: int
) -> NDArray[np.float64]:
    """Per panorama row, the columns one raw-image sample spans along its circle, (height,).

    A sample 1 / ``supersample`` pixels wide at radius r spans ``1 / (supersample * r)``
    radians of azimuth; near the inner radius that is many panorama columns.
    """
    elevation = pano_geometry.row_to_elevation(np.arange(pano_geometry.height))
    radius = np.maximum(raw_geometry.elevation_to_radius(elevation), 0.5)
    return 1.0 / (supersample * radius * pano_geometry.column_step)


def tangential_prefilter(
    panorama: np.ndarray,
    pano_geometry: PanoramaGeometry,
    raw_geometry: CatadioptricGeometry,
    supersample: int = 2,
) -> np.ndarray:
    """Average each panorama row over the columns one raw sample spans (a box along the row,
    wrapping round), so that :func:`fold` does not alias where the raw image compresses many
    columns into one pixel (near its inner radius). Rows whose span is under one column are
    unchanged. ``panorama`` (height, width) float; returns float32 of the same shape.
    """
    widths = tangential_widths(pano_geometry, raw_geometry, supersample)
    rows = np.flatnonzero(widths > 1.0)
    out = np.array(panorama, dtype=np.float32, copy=True)
    if rows.size == 0:
        return out
    h, w = panorama.shape
    block = np.asarray(panorama, dtype=np.float64)[rows]
    # cumulative sums over the row tripled (wrap-around), read at fractional column edges
    tripled = np.concatenate([block, block, block], axis=1)
    cumulative = np.concatenate([np.zeros((len(rows), 1)), np.cumsum(tripled, axis=1)], axis=1)
    half = np.minimum(widths[rows], w) / 2.0  # (n,)
    centre = np.arange(w) + w + 0.5  # column centres in the tripled row
    grid = np.arange(3 * w + 1, dtype=np.float64)

    def integral(edges: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(e, grid, c) for e, c in zip(edges, cumulative, strict=True)])

    upper, lower = centre[None, :] + half[:, None], centre[None, :] - half[:, None]
    out[rows] = ((integral(upper) - integral(lower)) / (2.0 * half[:, None])).astype(np.float32)
    return out


def fold(
    panorama: np.ndarray,
    pano_geometry: PanoramaGeometry,
    raw_geometry: CatadioptricGeometry,
    supersample: int = 2,
) -> np.ndarray:
    """Unfolded panorama (height, width) -> raw catadioptric image (H, W), black off the annulus.

    Bilinear, supersampled ``s x s`` then area-averaged; azimuth wraps (column 0 and the last
    column are neighbours); elevations beyond the panorama repeat its first / last row.
    The dtype is preserved.
    """
    column, row, mask = fold_maps(pano_geometry, raw_geometry, supersample)
    wrapped = np.concatenate([panorama[:, -1:], panorama, panorama[:, :1]], axis=1)
    out = cv2.remap(
        wrapped, column + np.float32(1.0), row, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
    )
    out[~mask] = 0
    return _area_average(out, supersample)


def frontmost(labels: np.ndarray, depth: np.ndarray, supersample: int) -> np.ndarray:
    """Per ``s x s`` block, the label of the sample with the smallest depth.

    ``labels`` and ``depth`` (h, w), h and w multiples of s; returns (h / s, w / s).
    """
    h, w = labels.shape
    s = supersample

    def blocks(a: np.ndarray) -> np.ndarray:
        return a.reshape(h // s, s, w // s, s).transpose(0, 2, 1, 3).reshape(h // s, w // s, -1)

    pick = np.argmin(blocks(depth), axis=2)[..., None]
    return np.take_along_axis(blocks(labels), pick, axis=2)[..., 0]


def fold_labels(
    labels: np.ndarray,
    depth: np.ndarray,
    pano_geometry: PanoramaGeometry,
    raw_geometry: CatadioptricGeometry,
    supersample: int = 2,
) -> np.ndarray:
    """Fold a label panorama (any dtype) with its depth (same shape) to a raw image.

    No interpolation: each raw pixel looks up the nearest panorama pixel at each of the
    ``s x s`` sample points of :func:`fold` and keeps the frontmost one's label (so thin objects
    are not lost). Pixels with no sample inside the annulus get 0.
    """
    column, row, mask = fold_maps(pano_geometry, raw_geometry, supersample)
    h, w = labels.shape
    r = np.clip(np.rint(row).astype(np.intp), 0, h - 1)
    c = np.rint(column).astype(np.intp) % w
    sampled = np.where(mask, labels[r, c], 0).astype(labels.dtype)
    return frontmost(sampled, np.where(mask, depth[r, c], np.inf), supersample)
