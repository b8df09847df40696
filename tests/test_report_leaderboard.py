"""`homebench leaderboard`: one metric of several runs' methods under each condition."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main
from homebench.errors import DataError
from homebench.report.across_runs.leaderboard import BOARD_METRICS, leaderboard

CONDITIONS = ("a-a", "a-b")


def _ahc(offset_deg: float) -> str:
    return f"{math.cos(math.radians(offset_deg)):.3f}"


@pytest.fixture
def runs(tmp_path: Path) -> tuple[Path, Path]:
    first = write_fake_run(
        tmp_path / "first",
        [FakeMethod("warping", 20.0), FakeMethod("sift", 5.0)],
        conditions=CONDITIONS,
    )
    second = write_fake_run(tmp_path / "second", [FakeMethod("klt", 30.0)], conditions=CONDITIONS)
    return first, second


def test_one_row_per_method_and_one_column_per_condition(runs) -> None:
    frame = leaderboard(runs).view.frame
    assert list(frame.columns) == ["method", *CONDITIONS]
    assert list(frame["method"]) == ["klt", "sift", "warping"]
    cells = frame.set_index("method")
    # every goal has the same AE: a zero-width interval; the smallest AE has the best AHC
    assert cells.loc["sift", "a-a"] == f"{_ahc(5)} [{_ahc(5)}, {_ahc(5)}] *"
    assert cells.loc["klt", "a-b"] == f"{_ahc(30)} [{_ahc(30)}, {_ahc(30)}]"


def test_mean_ae_marks_the_smallest(runs) -> None:
    cells = leaderboard(runs, metric="mean_ae_deg").view.frame.set_index("method")
    assert cells.loc["sift", "a-b"] == "5.00 [5.00, 5.00] *"
    assert cells.loc["warping", "a-b"] == "20.00 [20.00, 20.00]"


def test_a_label_with_other_parameters_in_another_run_gets_one_row_per_run(
    tmp_path: Path,
) -> None:
    a = write_fake_run(tmp_path / "a", [FakeMethod("warping", 10.0)])
    b = write_fake_run(tmp_path / "b", [FakeMethod("warping", 10.0)], conditions=("b-b",))
    merged = leaderboard([a, b]).view.frame
    assert list(merged["method"]) == ["warping"] and list(merged.columns) == [
        "method",
        "a: a-a",
        "b: b-b",
    ]
    config = json.loads((b / "config.resolved.json").read_text())
    config["methods"][0]["params"] = {"ratio": 0.7}
    (b / "config.resolved.json").write_text(json.dumps(config))
    split = leaderboard([a, b]).view.frame
    assert list(split["method"]) == ["a: warping", "b: warping"]
    assert list(split.set_index("method").loc["a: warping"]) == [
        f"{_ahc(10)} [{_ahc(10)}, {_ahc(10)}] *",
        "--",
    ]


def test_cli_writes_the_table_file_and_an_index_page(runs, tmp_path: Path) -> None:
    (runs[0] / "report").mkdir()
    (runs[0] / "report" / "report.pdf").write_bytes(b"%PDF")
    out, page = tmp_path / "out" / "board.csv", tmp_path / "out" / "index.html"
    args = [
        "leaderboard",
        *map(str, runs),
        "--metric",
        "rr",
        "--out",
        str(out),
        "--html",
        str(page),
    ]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("**RR [95 % interval] per method and condition (*: best RR")
    assert sorted(out.parent.iterdir()) == [out, page]
    assert out.read_text().splitlines()[0] == "method,a-a,a-b"
    index = page.read_text()
    assert '<a href="../first/report/report.pdf">first</a>' in index
    assert "<li>second: no report</li>" in index
    result = CliRunner().invoke(main, ["leaderboard", str(runs[0]), "--metric", "speed"])
    assert result.exit_code == 2


def test_columns_are_keyed_by_world_and_the_best_is_marked_within_a_column(
    tmp_path: Path,
) -> None:
    """A quick-start world and a full set both have an "a-a" condition: they are two columns,
    each with its own best."""
    small = write_fake_run(tmp_path / "small", [FakeMethod("warping", 20.0)], world="small")
    large = write_fake_run(
        tmp_path / "large", [FakeMethod("sift", 5.0), FakeMethod("klt", 8.0)], world="large"
    )
    frame = leaderboard([small, large]).view.frame
    small_aa, large_aa = "small: a-a @ db-a-small", "large: a-a @ db-a-large"
    assert list(frame.columns) == ["method", small_aa, large_aa]
    cells = frame.set_index("method")
    assert cells.loc["warping", small_aa].endswith(" *")
    assert cells.loc["sift", large_aa].endswith(" *")
    assert not cells.loc["klt", large_aa].endswith(" *")
    assert cells.loc["warping", large_aa] == "--"
    # runs over the same databases share their columns, named by condition alone
    again = write_fake_run(tmp_path / "again", [FakeMethod("min", 1.0)], world="large")
    frame = leaderboard([large, again]).view.frame
    assert list(frame.columns) == ["method", "a-a"]
    assert frame.set_index("method").loc["min", "a-a"].endswith(" *")


def test_a_column_not_in_every_run_names_the_runs_that_hold_it(tmp_path: Path) -> None:
    """Runs of other worlds: 'original-day | original-original | ant-ant' said nothing of
    where each column came from. A column in every run keeps its condition's name."""
    quick = write_fake_run(tmp_path / "quick", [FakeMethod("warping", 20.0)],
                           conditions=("a-a", "a-b"), world="small")  # fmt: skip
    again = write_fake_run(tmp_path / "again", [FakeMethod("sift", 8.0)], conditions=("a-a",),
                           world="small")  # fmt: skip
    ant = write_fake_run(tmp_path / "ant", [FakeMethod("warping", 10.0)], conditions=("c-c",),
                         world="ant")  # fmt: skip
    board = leaderboard([quick, again, ant]).view
    assert list(board.frame.columns) == ["method", "quick, again: a-a", "quick: a-b", "ant: c-c"]
    shared = leaderboard([quick, again]).view
    assert list(shared.frame.columns) == ["method", "a-a", "quick: a-b"]
    assert "a column named by its condition alone is in every run" in " ".join(shared.notes)
    alone = leaderboard([quick]).view  # its one note: its intervals rest on 2 goals
    assert [note for note in alone.notes if "goals" not in note] == []
    assert "quick: " not in " ".join(alone.frame.columns)
    out = tmp_path / "board.csv"
    args = ["leaderboard", str(quick), str(ant), "--out", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert out.read_text().splitlines()[0] == "method,quick: a-a,quick: a-b,ant: c-c"
    assert "| quick: a-a " in result.stdout


def test_a_method_without_home_directions_is_never_ranked(tmp_path: Path) -> None:
    methods = [FakeMethod("compass", 0.0, gives_direction=False), FakeMethod("warping", 30.0)]
    run = write_fake_run(tmp_path / "run", methods)
    for metric in ("ahc", "rr", "mean_ae_deg"):
        cells = leaderboard([run], metric=metric).view.frame.set_index("method")
        assert cells.loc["compass", "a-a"] == "--"
        assert cells.loc["warping", "a-a"].endswith(" *")


#: Positions at which "holes" gives no estimate: 3 of the 19 pairs of each goal.
HOLES = frozenset({(0, 0), (3, 4), (2, 0)})


def _ae90(offset_deg: float) -> str:
    """The AHC of "holes" (``offset_deg`` off) with its 3 missing estimates of 19 as 90 deg."""
    return _ahc((16 * offset_deg + 3 * 90) / 19)


@pytest.fixture
def abstaining(tmp_path: Path) -> tuple[Path, Path]:
    """Two runs: "holes" errs least where it answers but abstains on 15.8 % of the pairs;
    "steady" answers every pair; "klt", of another run, holds a-b only and beats both."""
    first = write_fake_run(
        tmp_path / "first",
        [FakeMethod("holes", 5.0, HOLES), FakeMethod("steady", 8.0)],
        conditions=CONDITIONS,
    )
    second = write_fake_run(tmp_path / "second", [FakeMethod("klt", 3.0)], conditions=("a-b",))
    return first, second


def _cells(runs: tuple[Path, Path], metric: str) -> pd.DataFrame:
    """The board's cells by method and condition (a-a: the first run's alone)."""
    frame = leaderboard(runs, metric=metric).view.frame.set_index("method")
    return frame.rename(columns={"first: a-a": "a-a"})


def test_an_abstaining_method_shows_its_ahc90_and_share_and_each_column_marks_its_best(
    abstaining,
) -> None:
    board = leaderboard(abstaining).view
    assert board.title == (
        "AHC [95 % interval] per method and condition; where a method gave no estimate for "
        "some pairs, then AHC (no estimate = 90 deg) / no estimate [%] (*: best AHC in its "
        "column)"
    )
    cells = board.frame.set_index("method").rename(columns={"first: a-a": "a-a"})
    # the paper's AHC ranks "holes" first in a-a, "klt" in a-b: one mark per column
    assert cells.loc["holes", "a-a"] == f"{_ahc(5)} [{_ahc(5)}, {_ahc(5)}] * / {_ae90(5)} / 15.8"
    assert cells.loc["holes", "a-b"] == f"{_ahc(5)} [{_ahc(5)}, {_ahc(5)}] / {_ae90(5)} / 15.8"
    assert cells.loc["steady", "a-a"] == f"{_ahc(8)} [{_ahc(8)}, {_ahc(8)}]"  # no abstention
    assert cells.loc["klt", "a-b"] == f"{_ahc(3)} [{_ahc(3)}, {_ahc(3)}] *"
    assert cells.loc["klt", "a-a"] == "--"
    for column in CONDITIONS:
        assert sum(cell.split(" / ")[0].endswith(" *") for cell in cells[column]) == 1
    # ranked on the AHC with a missing estimate as 90 deg, "steady" beats "holes" in a-a
    cells = _cells(abstaining, "ahc_missing90")
    assert cells.loc["steady", "a-a"] == f"{_ahc(8)} [{_ahc(8)}, {_ahc(8)}] *"
    assert cells.loc["holes", "a-a"] == f"{_ae90(5)} [{_ae90(5)}, {_ae90(5)}] / {_ahc(5)} / 15.8"
    cells = _cells(abstaining, "mean_ae_deg")
    assert cells.loc["holes", "a-a"] == "5.00 [5.00, 5.00] * / 15.8"
    cells = _cells(abstaining, "no_estimate_share")
    assert cells.loc["steady", "a-a"] == "0.0 [0.0, 0.0] *"
    assert cells.loc["holes", "a-a"] == "15.8 [15.8, 15.8]"


def _define_ahc(run: Path, definition: str) -> None:
    config = json.loads((run / "config.resolved.json").read_text())
    config["metrics"]["ahc"]["definition"] = definition
    (run / "config.resolved.json").write_text(json.dumps(config))


def test_the_title_names_the_runs_ahc_definition_and_two_definitions_do_not_rank_together(
    abstaining,
) -> None:
    for run in abstaining:
        _define_ahc(run, "mean_cos")
    board = leaderboard(abstaining).view
    assert board.title.startswith("AHC (mean cos) [95 % interval] per method and condition")
    assert "then AHC (mean cos; no estimate = 90 deg) / no estimate [%]" in board.title
    # the mean of cos(AE): the 3 missing of 19 pairs add nothing
    mean_cos90 = f"{math.cos(math.radians(5)) * 16 / 19:.3f}"
    holes = board.frame.set_index("method").loc["holes", "first: a-a"]
    assert holes == f"{_ahc(5)} [{_ahc(5)}, {_ahc(5)}] * / {mean_cos90} / 15.8"
    _define_ahc(abstaining[1], "cos_mean_ae")
    for metric in ("ahc", "ahc_missing90"):
        with pytest.raises(DataError, match="first and second define the AHC otherwise"):
            leaderboard(abstaining, metric=metric)
    assert leaderboard(abstaining, metric="rr").view.title.startswith("RR [95 % interval]")


def test_two_return_ratio_settings_do_not_rank_together(abstaining) -> None:
    config = json.loads((abstaining[1] / "config.resolved.json").read_text())
    config["metrics"]["return_ratio"]["no_estimate"] = "arrived"
    (abstaining[1] / "config.resolved.json").write_text(json.dumps(config))
    with pytest.raises(DataError, match="first and second define the RR otherwise") as refused:
        leaderboard(abstaining, metric="rr")
    assert "no_estimate fail" in str(refused.value) and "no_estimate arrived" in str(refused.value)
    assert leaderboard(abstaining, metric="ahc").view.title.startswith("AHC")


def test_intervals_over_few_goals_carry_the_reports_note(runs, tmp_path: Path) -> None:
    assert any("rest on 2 goals, fewer than 5" in note for note in leaderboard(runs).view.notes)
    goals = [(1, 2), (2, 3), (3, 1), (0, 2), (3, 3)]
    many = [
        write_fake_run(tmp_path / name, [FakeMethod(label, 10.0)], goals, CONDITIONS)
        for name, label in (("five", "warping"), ("other", "sift"))
    ]
    assert not any("fewer than" in note for note in leaderboard(many).view.notes)


def test_the_cli_offers_every_board_metric() -> None:
    (option,) = [p for p in main.commands["leaderboard"].params if p.name == "metric"]
    assert sorted(option.type.choices) == sorted(BOARD_METRICS)


def test_missing_jobs_are_reported(runs) -> None:
    """A deleted job file: the method was ranked on the goals left without a word."""
    first, second = runs
    victim = sorted((first / "jobs").glob("*.json"))[0]
    victim.unlink()
    result = CliRunner().invoke(main, ["leaderboard", str(first), str(second)])
    assert result.exit_code == 0, result.output
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"homebench: warning: first: missing jobs/{victim.name} ("), line
