"""Metrics that do not blend regimes: the headline metrics per distance band, and the share of
rotation estimates that took a view for its opposite (flips), on made-up runs whose every
value is known."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_report_runs import GRID, FakeMethod, write_fake_run

from homebench.analysis.tables import flipped
from homebench.config import MetricsConfig
from homebench.errors import ConfigError
from homebench.evaluation.results import build_tables

GOALS = ((1, 2), (2, 3))


def _distances(goal: tuple[int, int]) -> np.ndarray:
    goal_xy = GRID.position(*goal)
    return np.array([np.hypot(*(GRID.position(i, j) - goal_xy)) for i, j in GRID.indices()
                     if (i, j) != goal])  # fmt: skip


def test_each_band_holds_the_pairs_of_its_distances(tmp_path: Path) -> None:
    near = FakeMethod("near-good", 10.0)
    metrics = MetricsConfig.model_validate({"band_edges_m": [0.5, 1.0]})
    tables = build_tables(write_fake_run(tmp_path, [near], GOALS), metrics)
    bands = tables.bands.set_index("band")
    assert list(bands.index) == ["0-0.5 m", "0.5-1 m", "from 1 m"]
    distance = np.concatenate([_distances(g) for g in GOALS])
    expected = [np.sum(distance < 0.5), np.sum((distance >= 0.5) & (distance < 1.0)),
                np.sum(distance >= 1.0)]  # fmt: skip
    assert list(bands["pairs"]) == expected and sum(expected) == len(distance)
    assert np.allclose(bands["mean_ae_deg"], 10.0)
    assert np.allclose(bands["ahc"], math.cos(math.radians(10.0)))
    assert list(bands["n_goals"]) == [2, 2, 1]  # one goal has no current beyond 1 m
    assert math.isinf(bands.loc["from 1 m", "high_m"])


def test_a_method_without_directions_keeps_its_rotation_errors_per_band(tmp_path: Path) -> None:
    compass = FakeMethod("compass", 170.0, gives_direction=False)
    tables = build_tables(write_fake_run(tmp_path, [compass], GOALS), MetricsConfig())
    bands = tables.bands
    assert bands[["ahc", "mean_ae_deg", "ahc_missing90"]].isna().all().all()
    filled = bands[bands["pairs"] > 0]
    assert np.allclose(filled["rotation_error_deg"], 170.0)
    assert np.allclose(filled["rotation_flip_share"], 1.0)


def test_the_flip_share_counts_errors_beyond_150_deg_among_the_rotation_estimates(
    tmp_path: Path,
) -> None:
    errors = np.radians([10.0, 149.0, 151.0, 180.0, np.nan])
    assert np.array_equal(flipped(errors)[:4], [0.0, 0.0, 1.0, 1.0])
    assert np.isnan(flipped(errors)[4])
    methods = [FakeMethod("flips", 160.0, gives_direction=False),
               FakeMethod("turns", 40.0, gives_direction=False)]  # fmt: skip
    summary = build_tables(write_fake_run(tmp_path, methods, GOALS), MetricsConfig()).summary
    shares = summary.set_index("method")["rotation_flip_share"]
    assert shares["flips"] == 1.0 and shares["turns"] == 0.0


@pytest.mark.parametrize("edges", [[], [1.0, 1.0], [2.0, 1.0], [-1.0], [float("inf")]])
def test_bad_band_edges_are_config_errors(edges: list[float]) -> None:
    with pytest.raises((ValueError, ConfigError)):
        MetricsConfig.model_validate({"band_edges_m": edges})


def test_the_band_table_is_written_with_the_run(tmp_path: Path, arena_manifest: Path) -> None:
    from conftest import arena_config, run_config

    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest))
    assert result.exit_code == 0, result.output
    bands = pd.read_csv(tmp_path / "run" / "tables" / "bands.csv")
    assert set(bands["band"]) == {"0-1.2 m", "1.2-2.4 m", "from 2.4 m"}
    assert bands.groupby(["condition", "method"])["pairs"].sum().eq(2 * 19).all()
