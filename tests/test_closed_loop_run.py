"""A closed-loop run end to end on a tiny world: CLI run and report, resume, --jobs 1 vs 2.

Tiny: 48-column panoramas, 12 starts 0.4 m apart around one goal, warping and both controls.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml
from click.testing import CliRunner

from homebench.cli import main
from homebench.report.tables import CONSOLE_WIDTH

TINY = {
    "kind": "closed-loop",
    "name": "tiny",
    "world": {"seed": 0, "grid": {"shape": [5, 5], "spacing": 0.3}, "unfolded": {"width": 48}},
    "methods": [{"method": "warping"}],
    "goals": [{"grid": [2, 2]}],
    "starts": {"spacing": 0.4},
    "motion": {"step_length": 0.1, "max_turn_deg": 30, "success_radius": 0.15},
}
#: Columns that measure time: they differ between any two runs.
TIMING = ("time_s", "see_s_per_step", "home_s_per_step", "s_per_step")


def _run(tmp_path: Path, name: str, *args: str) -> tuple[Path, str]:
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**TINY, "output": str(tmp_path / name)}))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", *args])
    assert result.exit_code == 0, result.output
    return tmp_path / name, result.stdout


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str, Path]:
    """The tiny run with --jobs 1 and with --jobs 2, tables only (CI time: the report of a
    closed-loop run, its three figures, is written by docs/tutorials/robots.md in a process of
    its own, the PDF by .ci/default-install)."""
    tmp_path = tmp_path_factory.mktemp("closed_loop")
    one, out = _run(tmp_path, "one", "--jobs", "1", "--no-report")
    two, _ = _run(tmp_path, "two", "--jobs", "2", "--no-report")
    return one, out, two


def test_run_writes_trials_and_tables(runs: tuple[Path, str, Path]) -> None:
    one, out, _ = runs
    assert "36 trial(s) computed, 0 reused" in out
    assert len(list((one / "trials").rglob("*.json"))) == 36
    summary = pd.read_csv(one / "tables" / "summary.csv")
    assert list(summary["method"]) == ["warping", "truth", "random"]
    truth = summary.set_index("method").loc["truth"]
    assert truth["success"] == 1.0 and truth["catchment_m2"] == pytest.approx(12 * 0.16)
    paired = pd.read_csv(one / "tables" / "paired.csv")
    assert len(paired) == 3 and (paired["starts"] == 12).all()


def test_the_console_summary_is_compact(runs: tuple[Path, str, Path]) -> None:
    """As narrow as the grid headline: no raw None or nan, and the summary table's columns
    stay in tables/summary.csv (the console shows those a reader needs first)."""
    one, out, _ = runs
    summary = [line for line in out.splitlines() if str(one) not in line]
    assert summary and max(len(line) for line in summary) <= CONSOLE_WIDTH, out
    assert not {"None", "nan", "NaN"} & set(out.split())
    assert "style posters" in out and "catchment [m^2]" in out and "collisions" not in out
    assert "collisions" in pd.read_csv(one / "tables" / "summary.csv").columns


def test_second_run_computes_nothing(runs: tuple[Path, str, Path], tmp_path: Path) -> None:
    one, _, _ = runs
    result = CliRunner().invoke(
        main, ["run", str(one.parent / "one.yaml"), "--no-progress", "--no-report"]
    )
    assert result.exit_code == 0 and "0 trial(s) computed, 36 reused" in result.stdout


@pytest.mark.parametrize("table", ["trials", "summary", "catchment", "paired"])
def test_jobs_1_and_2_give_identical_tables(runs: tuple[Path, str, Path], table: str) -> None:
    one, _, two = runs
    a, b = (pd.read_csv(run / "tables" / f"{table}.csv") for run in (one, two))
    timing = [c for c in TIMING if c in a]
    pd.testing.assert_frame_equal(a.drop(columns=timing), b.drop(columns=timing), check_exact=True)


def test_on_a_grid_database_the_robot_sees_the_nearest_grid_image(tmp_path: Path) -> None:
    """The same loop on a grid database: the view at a pose is the nearest grid image turned
    to the pose's heading by whole columns; truth still homes from every start."""
    import numpy as np

    from homebench.data.generate import generate
    from homebench.data.synth.spec import WorldSpec
    from homebench.experiments.closed_loop.config import ClosedLoopConfig
    from homebench.experiments.closed_loop.experiment import (
        run_closed_loop_experiment,
        trial_scene,
    )
    from homebench.experiments.closed_loop.views import LatticeViews
    from homebench.geometry import Pose

    spec = WorldSpec.model_validate({**TINY["world"], "grid": {"shape": [3, 3], "spacing": 0.3}})
    root = generate(spec, tmp_path / "db", jobs=1, name="tiny-grid")
    data = {**TINY, "world": None, "database": str(root / "manifest.yaml")}
    data = {k: v for k, v in data.items() if v is not None}
    config = ClosedLoopConfig.model_validate(
        {**data, "output": str(tmp_path / "run"), "goals": [{"grid": [1, 1]}],
         "starts": {"spacing": 0.3}}
    )  # fmt: skip
    outcome = run_closed_loop_experiment(config, tmp_path / "c.yaml", jobs=1, show_progress=False)
    assert not outcome.failures
    summary = outcome.table.set_index("method")
    assert summary.loc["truth", "success"] == 1.0 and summary.loc["truth", "trials"] == 8
    scene = trial_scene(config, "database")
    views = LatticeViews(scene, None, None, 0.0, 0, 0)
    assert scene.grid is not None
    corner = scene.grid.pose(0, 0)
    quarter = np.pi / 2  # 12 columns of 48
    seen = views.see(Pose(corner.x + 0.1, corner.y - 0.1, quarter))
    at_zero = views.see(corner)
    assert any(np.array_equal(seen, np.roll(at_zero, s, axis=1)) for s in (12, -12))
    assert not np.array_equal(seen, at_zero)
