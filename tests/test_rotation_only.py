"""A method that gives no home direction (a visual compass: rotations only) has no direction
metric anywhere: not an AHC of 0 from counting every pair as 90 deg, not an RR of the goal
alone, not a rank. Its rotation error stays."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import yaml
from click.testing import CliRunner
from conftest import arena_config, run_config
from test_report_runs import FakeMethod, write_fake_run

from homebench.analysis.tables import DIRECTION_COLUMNS
from homebench.cli import main
from homebench.config import MetricsConfig
from homebench.evaluation.results import build_tables


def test_a_compass_has_no_direction_metric_and_keeps_its_rotation_error(tmp_path: Path) -> None:
    methods = [FakeMethod("compass", 7.0, gives_direction=False), FakeMethod("m", 10.0)]
    metrics = MetricsConfig.model_validate({"catchment": True})
    tables = build_tables(write_fake_run(tmp_path, methods), metrics)
    summary = tables.summary.set_index("method")
    assert summary.loc["compass", DIRECTION_COLUMNS].isna().all()
    assert math.isclose(summary.loc["compass", "rotation_error_deg"], 7.0)
    assert summary.loc["m", DIRECTION_COLUMNS].notna().all()
    for table in (tables.goals, tables.ahc, tables.rr_starts):
        assert set(table["method"]) == {"m"}
    assert "compass" not in set(tables.comparisons[["method_a", "method_b"]].stack())


def test_a_real_visual_compass_run_is_na_in_every_direction_column(
    tmp_path: Path, arena_manifest: Path
) -> None:
    methods = [{"method": "visual-compass"}, {"method": "warping"}]
    config = arena_config(tmp_path, arena_manifest, methods=methods)
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv").set_index("method")
    assert summary.loc["visual-compass", ["rr", "ahc_missing90", "no_estimate_share"]].isna().all()
    assert summary.loc["visual-compass", "rotation_error_deg"] < 10.0
    assert summary.loc["warping", ["rr", "ahc"]].notna().all()


def test_a_closed_loop_robot_cannot_be_steered_by_a_compass(tmp_path: Path) -> None:
    config = yaml.safe_load(Path("configs/closed_loop.yaml").read_text())
    config |= {"output": str(tmp_path / "run"), "methods": [{"method": "visual-compass"}]}
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress"])
    assert result.exit_code == 2, result.output
    assert "methods.0: visual-compass gives no home direction" in result.stderr
    assert not (tmp_path / "run").exists()
