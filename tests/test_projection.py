"""Catadioptric <-> panorama projection against bearings we place ourselves."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry
from homebench.imaging.projection import (
    fold,
    fold_labels,
    fold_maps,
    frontmost,
    tangential_prefilter,
    tangential_widths,
    unfold,
)

RAW = CatadioptricGeometry(
    width=400,
    height=300,
    centre=(199.5, 149.5),
    radii=(20.0, 140.0),
    elevations=(np.radians(-50), np.radians(45)),
    direction="cw",
    zero_angle=np.pi / 2,
)
PANO = PanoramaGeometry(
    width=540, height=143, elevation_top=np.radians(45), elevation_bottom=np.radians(-50)
)

RAW_VARIANTS = [
    RAW,
    CatadioptricGeometry(
        400, 300, (201.0, 148.3), (20.0, 140.0), (np.radians(-50), np.radians(45)), "ccw", 0.7
    ),
    # mirror imaging "up" inside the horizon circle
    CatadioptricGeometry(
        400, 300, (199.5, 149.5), (20.0, 140.0), (np.radians(45), np.radians(-50)), "cw", -2.0
    ),
]
PANO_VARIANTS = [
    PANO,
    PanoramaGeometry(540, 143, np.radians(45), np.radians(-50), direction="cw", zero_column=77.0),
]


def _blob(shape: tuple[int, int], x: float, y: float, sigma: float, wrap_width: int = 0):
    """A Gaussian spot centred at (x, y); horizontally periodic when ``wrap_width`` > 0."""
    v, u = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float64)
    du = u - x
    if wrap_width:
        du = (du + wrap_width / 2) % wrap_width - wrap_width / 2
    return 200.0 * np.exp(-(du**2 + (v - y) ** 2) / (2 * sigma**2))


def _centroid(image: np.ndarray, x: float, y: float, radius: int, wrap: bool = False):
    """Intensity-weighted centroid of ``image`` in a window around (x, y)."""
    h, w = image.shape
    cols = np.arange(int(x) - radius, int(x) + radius + 2)
    rows = np.arange(max(int(y) - radius, 0), min(int(y) + radius + 2, h))
    patch = image[np.ix_(rows, cols % w if wrap else cols)].astype(np.float64)
    patch = np.maximum(patch - patch.max() * 0.05, 0)
    total = patch.sum()
    return (patch.sum(axis=0) @ cols) / total, (patch.sum(axis=1) @ rows) / total


BEARINGS = [(0.0, 0.0), (1.0, 0.3), (-2.5, -0.5), (np.pi - 0.004, 0.1), (-1.6, 0.6)]


@pytest.mark.parametrize("raw", RAW_VARIANTS)
@pytest.mark.parametrize("pano", PANO_VARIANTS)
@pytest.mark.parametrize(("azimuth", "elevation"), BEARINGS)
def test_marker_lands_at_its_bearing_both_ways(raw, pano, azimuth, elevation):
    # panorama -> raw
    col, row = pano.azimuth_to_column(azimuth), pano.elevation_to_row(elevation)
    spot = _blob((pano.height, pano.width), float(col), float(row), 2.0, pano.width)
    folded = fold(spot.astype(np.float32), pano, raw)
    u, v = raw.bearing_to_pixel(azimuth, elevation)
    cu, cv = _centroid(folded, float(u), float(v), 12)
    assert np.hypot(cu - u, cv - v) < 0.35
    # raw -> panorama
    spot = _blob((raw.height, raw.width), float(u), float(v), 1.5)
    unfolded = unfold(spot.astype(np.float32), raw, pano)
    cc, cr = _centroid(unfolded, float(col), float(row), 12, wrap=True)
    dc = (cc - col + pano.width / 2) % pano.width - pano.width / 2
    assert abs(dc) < 0.35 and abs(cr - row) < 0.35


def test_azimuth_sense_and_zero_are_honoured():
    """A marker at azimuth +90 deg (left of the heading) sits where each convention puts it."""
    # "cw" with zero at the top: azimuth grows clockwise on screen, so +90 deg is at the right
    u, v = RAW.bearing_to_pixel(np.pi / 2, 0.0)
    assert u == pytest.approx(RAW.centre[0] + RAW.horizon_radius) and v == pytest.approx(
        RAW.centre[1]
    )
    spot = _blob((PANO.height, PANO.width), PANO.width / 4, PANO.horizon_row, 2.0, PANO.width)
    folded = fold(spot.astype(np.float32), PANO, RAW)
    cu, cv = _centroid(folded, float(u), float(v), 12)
    assert np.hypot(cu - u, cv - v) < 0.35
    # in a cw panorama with zero column 77, +90 deg is a quarter turn to the left of 77
    cw = PANO_VARIANTS[1]
    assert cw.azimuth_to_column(np.pi / 2) == pytest.approx(77.0 - cw.width / 4 + cw.width)


@pytest.mark.parametrize("raw", RAW_VARIANTS)
def test_horizon_circle_maps_to_horizon_row(raw):
    v, u = np.mgrid[0 : raw.height, 0 : raw.width]
    radius = np.hypot(u - raw.centre[0], v - raw.centre[1])
    ring = np.exp(-((radius - raw.horizon_radius) ** 2) / 2.0).astype(np.float32)
    profile = unfold(ring, raw, PANO).mean(axis=1)
    rows = np.arange(PANO.height)
    peak = int(np.argmax(profile))
    window = slice(peak - 3, peak + 4)
    centre = (profile[window] @ rows[window]) / profile[window].sum()
    assert centre == pytest.approx(PANO.horizon_row, abs=0.1)
    # and back: the horizon row folds onto the horizon circle
    band = np.zeros((PANO.height, PANO.width), np.float32)
    band[int(round(PANO.horizon_row)) - 1 : int(round(PANO.horizon_row)) + 2] = 1.0
    folded = fold(band, PANO, raw)
    lit = radius[folded > 0.5]
    assert abs(np.median(lit) - raw.horizon_radius) < 0.5


@pytest.mark.parametrize("raw", RAW_VARIANTS)
@pytest.mark.parametrize("pano", PANO_VARIANTS)
def test_round_trip_of_a_smooth_panorama(raw, pano):
    rng = np.random.default_rng(0)
    coarse = rng.uniform(0, 255, size=(8, 24)).astype(np.float32)
    # periodic in azimuth: tile, resize, crop the middle copy
    tiled = cv2.resize(
        np.tile(coarse, (1, 3)), (3 * pano.width, pano.height), interpolation=cv2.INTER_CUBIC
    )
    image = np.ascontiguousarray(tiled[:, pano.width : 2 * pano.width])
    back = unfold(fold(image, pano, raw), raw, pano)
    inner = slice(3, pano.height - 3)  # the annulus rims blend with the black outside
    error = np.abs(back[inner] - image[inner])
    assert np.median(error) < 0.5 and np.percentile(error, 99) < 3.0


def test_fold_blackens_outside_the_annulus_and_keeps_dtype():
    image = np.full((PANO.height, PANO.width), 180, np.uint8)
    folded = fold(image, PANO, RAW)
    assert folded.dtype == np.uint8 and folded.shape == (RAW.height, RAW.width)
    v, u = np.mgrid[0 : RAW.height, 0 : RAW.width]
    radius = np.hypot(u - RAW.centre[0], v - RAW.centre[1])
    assert np.all(folded[(radius < RAW.inner_radius - 1) | (radius > RAW.outer_radius + 1)] == 0)
    assert np.all(folded[(radius > RAW.inner_radius + 1) & (radius < RAW.outer_radius - 1)] == 180)
    assert unfold(folded, RAW, PANO).dtype == np.uint8


def test_frontmost_picks_the_nearest_sample_of_each_block():
    labels = np.array([[1, 2, 3, 4], [5, 6, 7, 8]])
    depth = np.array([[9.0, 1.0, 5.0, 5.0], [3.0, 2.0, 4.0, 0.5]])
    assert frontmost(labels, depth, 2).tolist() == [[2, 8]]


def test_fold_labels_keeps_thin_near_objects():
    labels = np.zeros((PANO.height, PANO.width), np.int32)
    depth = np.full(labels.shape, 10.0)
    labels[:, 100:200], depth[:, 100:200] = 3, 5.0  # a wide object
    labels[:, 150], depth[:, 150] = 5, 1.0  # a one-column pole in front of it
    labels[:, -2:] = 9  # at the seam
    out = fold_labels(labels, depth, PANO, RAW)
    assert out.dtype == np.int32 and out.shape == (RAW.height, RAW.width)
    assert set(np.unique(out)) == {0, 3, 5, 9}
    pole = fold((labels == 5).astype(np.float32), PANO, RAW)
    assert np.all(out[pole > 0.5] == 5)
    v, u = np.mgrid[0 : RAW.height, 0 : RAW.width]
    radius = np.hypot(u - RAW.centre[0], v - RAW.centre[1])
    assert np.all(out[radius > RAW.outer_radius + 1] == 0)


def test_maps_are_cached_and_read_only():
    a = fold_maps(PANO, RAW, 2)
    assert fold_maps(PANO, RAW, 2) is a
    with pytest.raises(ValueError):
        a[0][0, 0] = 1.0


def test_tangential_prefilter_stops_aliasing_near_the_inner_radius():
    """Columns alternating 0 / 200 (a texture finer than the raw image resolves near its
    inner radius): folded as they are, the inner ring aliases into a pattern; prefiltered,
    it is the mean grey. Rows whose raw samples span less than a column are untouched, and
    every row keeps its mean (a box average of a periodic row)."""
    raw = CatadioptricGeometry(
        width=300, height=300, centre=(149.5, 149.5), radii=(20.0, 140.0),
        elevations=(np.radians(-50.0), np.radians(45.0)), direction="cw",
        zero_angle=np.pi / 2,
    )  # fmt: skip
    pano = PanoramaGeometry(1440, 380, np.radians(45.0), np.radians(-50.0))
    stripes = np.zeros((pano.height, pano.width), np.float32)
    stripes[:, ::2] = 200.0
    filtered = tangential_prefilter(stripes, pano, raw, 2)
    widths = tangential_widths(pano, raw, 2)
    assert np.array_equal(filtered[widths <= 1], stripes[widths <= 1])
    assert np.allclose(filtered.mean(axis=1), stripes.mean(axis=1), atol=1e-3)
    v, u = np.mgrid[0:300, 0:300]
    ring = np.abs(np.hypot(u - 149.5, v - 149.5) - 30.0) < 3  # raw samples span ~4 columns
    aliased, clean = fold(stripes, pano, raw, 2)[ring], fold(filtered, pano, raw, 2)[ring]
    assert aliased.std() > 20.0
    assert clean.std() < 0.1 * aliased.std() and abs(clean.mean() - 100.0) < 2.0
