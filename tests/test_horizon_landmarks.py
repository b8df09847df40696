"""Horizon segmentation into dark and bright sectors (shared by ALV and the snapshot model)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from landmark_scene import landmark_view

from homebench.errors import ConfigError
from homebench.geometry import Pose
from homebench.methods.landmarks.alv import AverageLandmarkVector
from homebench.methods.landmarks.horizon import (
    horizon_sectors,
    merge_narrow,
    otsu_threshold,
    threshold,
)

STEP = 2.0 * math.pi / 12


def test_sectors_alternate_and_a_run_may_wrap_around_column_zero():
    signal = np.array([0, 0, 9, 9, 9, 0, 9, 9, 9, 9, 0, 0], dtype=float)  # mean 5.25
    sectors = horizon_sectors(signal)
    # runs: dark 10..1 (wraps, 4 columns), bright 2..4, dark 5, bright 6..9
    order = np.argsort(sectors.centres % (2 * math.pi))
    np.testing.assert_allclose(
        sectors.centres[order] % (2 * math.pi), np.array([3.0, 5.0, 7.5, 11.5]) * STEP
    )
    np.testing.assert_allclose(sectors.widths[order], np.array([3, 1, 4, 4]) * STEP)
    assert sectors.dark[order].tolist() == [False, True, False, True]
    assert sectors.of_kind("dark").centres.size == 2
    assert sectors.of_kind("bright").dark.tolist() == [False, False]


def test_a_flat_or_one_sided_signal_has_no_sectors():
    for signal in (np.full(12, 7.0), np.zeros(12)):
        sectors = horizon_sectors(signal)
        assert sectors.centres.size == sectors.widths.size == sectors.dark.size == 0


def test_threshold_rules():
    signal = np.array([0.0, 1.0, 2.0, 9.0])
    assert threshold(signal, "mean") == 3.0
    assert threshold(signal, "median") == 1.5
    assert threshold(signal, "otsu") == 5.5  # {0, 1, 2} | {9}: the largest between-class variance
    dark_mean = horizon_sectors(signal, "mean").of_kind("dark")
    dark_median = horizon_sectors(signal, "median").of_kind("dark")
    np.testing.assert_allclose(dark_mean.widths, [3 * math.pi / 2])
    np.testing.assert_allclose(dark_median.widths, [math.pi])


def test_otsu_separates_two_populations_exactly():
    """Between-class variance of the split after k sorted values, by hand: 3 dark values of 10,
    20, 30 and 9 bright of 200: splitting after the third (means 20 and 200) beats every other
    split, so the threshold is midway between 30 and 200; a flat signal gives its value."""
    signal = np.array([200.0] * 9 + [10.0, 20.0, 30.0])
    assert otsu_threshold(signal) == 115.0
    assert otsu_threshold(np.full(5, 7.0)) == 7.0
    assert otsu_threshold(np.array([3.0])) == 3.0


def _lit_wall(n: int = 360) -> np.ndarray:
    """A bright wall lit unevenly (grey 150 +- 15 over the turn, dimmest at column 220) with
    three black landmarks (grey 20) of 8, 12 and 6 columns centred on columns 40, 160 and
    280."""
    column = np.arange(n)
    signal = 150.0 + 15.0 * np.cos(2.0 * np.pi * (column - 40) / n)
    for centre, width in ((40, 8), (160, 12), (280, 6)):
        signal[centre - width // 2 : centre + width // 2] = 20.0
    return signal


def test_an_unevenly_lit_wall_needs_two_classes():
    """Otsu's level falls between the landmarks and the wall: exactly the three landmarks. The
    mean (141) lies within the wall's range, so the dim wall round column 220 is a fourth dark
    sector."""
    step = 2.0 * math.pi / 360
    otsu = horizon_sectors(_lit_wall(), "otsu").of_kind("dark")
    np.testing.assert_allclose(
        np.sort(otsu.centres % (2 * math.pi)), np.array([39.5, 159.5, 279.5]) * step
    )
    np.testing.assert_allclose(np.sort(otsu.widths), np.array([6, 8, 12]) * step)
    mean = horizon_sectors(_lit_wall(), "mean").of_kind("dark")
    assert mean.centres.size == 4
    assert np.any(np.abs(mean.centres % (2 * math.pi) - 219.5 * step) < 2 * step)


def test_narrow_runs_merge_into_their_neighbours_narrowest_first():
    dark = np.array([1, 1, 1, 0, 1, 1, 1, 1, 0, 0, 1, 1], dtype=bool)
    # runs: dark 10..2 (5, wraps), bright 3 (1), dark 4..7 (4), bright 8..9 (2)
    assert merge_narrow(dark, 2).tolist() == [1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 1, 1]
    assert merge_narrow(dark, 3).tolist() == [True] * 12
    assert merge_narrow(dark, 1).tolist() == dark.tolist()
    sectors = horizon_sectors(dark.astype(float), "otsu", min_width=2.5 * STEP)
    assert sectors.centres.size == 0  # the bright runs (1 and 2 columns) merged away


def test_describe_finds_the_four_cylinders_of_the_cross():
    signal = AverageLandmarkVector().describe(landmark_view(Pose(0.0, 0.0, 0.0)))
    assert signal.shape == (288,)
    dark = horizon_sectors(signal).of_kind("dark")
    np.testing.assert_allclose(np.sort(dark.centres), [-math.pi, -math.pi / 2, 0, math.pi / 2])


def test_blur_low_passes_the_signal_in_azimuth():
    """A Gaussian of 2 deg keeps the signal's mean and softens its edges (the steepest step
    between columns at most half as steep); the cross's four cylinders stay where they are."""
    view = landmark_view(Pose(0.0, 0.0, 0.0))
    sharp = AverageLandmarkVector().describe(view)
    blurred = AverageLandmarkVector(blur_deg=2.0).describe(view)
    assert blurred.mean() == pytest.approx(sharp.mean())
    assert np.abs(np.diff(blurred)).max() < 0.5 * np.abs(np.diff(sharp)).max()
    dark = horizon_sectors(blurred).of_kind("dark")
    np.testing.assert_allclose(np.sort(dark.centres), [-math.pi, -math.pi / 2, 0, math.pi / 2])


@pytest.mark.parametrize(
    "params",
    [
        {"band_half_width_deg": 0.0},
        {"n_columns": 2},
        {"threshold": "kmeans"},
        {"blur_deg": -1.0},
        {"min_width_deg": 180.0},
    ],
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        AverageLandmarkVector(**params)
