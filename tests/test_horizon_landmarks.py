"""Horizon segmentation into dark and bright sectors (shared by ALV and the snapshot model)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from landmark_scene import landmark_view

from homebench.errors import ConfigError
from homebench.geometry import Pose
from homebench.methods.alv import AverageLandmarkVector
from homebench.methods.horizon_landmarks import horizon_sectors, threshold

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
    dark_mean = horizon_sectors(signal, "mean").of_kind("dark")
    dark_median = horizon_sectors(signal, "median").of_kind("dark")
    np.testing.assert_allclose(dark_mean.widths, [3 * math.pi / 2])
    np.testing.assert_allclose(dark_median.widths, [math.pi])


def test_describe_finds_the_four_cylinders_of_the_cross():
    signal = AverageLandmarkVector().describe(landmark_view(Pose(0.0, 0.0, 0.0)))
    assert signal.shape == (288,)
    dark = horizon_sectors(signal).of_kind("dark")
    np.testing.assert_allclose(np.sort(dark.centres), [-math.pi, -math.pi / 2, 0, math.pi / 2])


@pytest.mark.parametrize(
    "params", [{"band_half_width_deg": 0.0}, {"n_columns": 2}, {"threshold": "otsu"}]
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        AverageLandmarkVector(**params)
