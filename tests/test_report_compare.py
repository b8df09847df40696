"""`homebench compare`: differences per condition and method against the first run."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main
from homebench.errors import DataError
from homebench.report.compare import compare_runs
from homebench.report.tables import to_csv


@pytest.fixture
def runs(tmp_path: Path) -> tuple[Path, Path]:
    a = write_fake_run(
        tmp_path / "a",
        [FakeMethod("warping", 10.0, home_ms=2.0, describe_ms=4.0), FakeMethod("old", 0.0)],
    )
    b = write_fake_run(
        tmp_path / "b",
        [FakeMethod("warping", 40.0, home_ms=6.0, describe_ms=1.0), FakeMethod("new", 0.0)],
    )
    return a, b


def test_differences_and_time_ratios_are_against_the_first_run(runs) -> None:
    a, b = runs
    comparison = compare_runs([a, b])
    table = comparison.table.set_index(["method", "run"])
    mine, reference = table.loc[("warping", str(b))], table.loc[("warping", str(a))]
    assert mine["mean AE [deg]"] == pytest.approx(40.0)
    assert mine["mean AE diff [deg]"] == pytest.approx(30.0)
    assert mine["AHC diff"] == pytest.approx(
        math.cos(math.radians(40)) - math.cos(math.radians(10))
    )
    assert mine["home time ratio"] == pytest.approx(3.0)
    assert mine["describe time ratio"] == pytest.approx(0.25)
    assert reference["mean AE diff [deg]"] == 0.0 and reference["home time ratio"] == 1.0
    # methods in one run only: their rows are there, without differences, and said so
    assert math.isnan(table.loc[("new", str(b)), "mean AE diff [deg]"])
    assert math.isnan(table.loc[("old", str(b)), "mean AE [deg]"])
    assert f"{b}: no results for old under a-a" in comparison.warnings
    assert f"{a}: no results for new under a-a" in comparison.warnings


def test_comparison_view_rounds_and_labels(runs) -> None:
    comparison = compare_runs(list(runs))
    csv = to_csv(comparison.view())
    assert csv.splitlines()[0].startswith("condition,method,run,mean AE [deg],mean AE diff [deg]")
    assert ",30.0," in csv and ",3.0" in csv


def test_compare_needs_two_runs_and_says_which_folder_is_wrong(runs, tmp_path: Path) -> None:
    with pytest.raises(DataError, match="at least two"):
        compare_runs([runs[0]])
    with pytest.raises(DataError, match="nowhere: no such run folder"):
        compare_runs([runs[0], tmp_path / "nowhere"])


def test_cli_compare_prints_and_writes_the_table(runs, tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["compare", *map(str, runs), "--out", str(tmp_path / "c")])
    assert result.exit_code == 0, result.output
    assert "| warping " in result.stdout and "30.00" in result.stdout
    assert "no results for old under a-a" in result.stderr
    for suffix in ("csv", "md", "tex"):
        assert (tmp_path / "c" / f"comparison.{suffix}").is_file()
    result = CliRunner().invoke(main, ["compare", str(runs[0])])
    assert result.exit_code == 2 and "at least two run folders" in result.stderr
