"""`homebench compare`: config differences, then changes against the first run with intervals,
p-values and regression thresholds.

The runs are made-up (``write_fake_run``): a method's AE is its offset at every pair, so each
change, interval and exact test p-value is known in advance.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main
from homebench.errors import ConfigError, DataError
from homebench.report.across_runs.compare import Threshold, compare_runs
from homebench.report.across_runs.run_set import run_labels
from homebench.report.tables import to_csv

#: Six goals: the exact sign-flip test can reach 2 / 2**6 < 0.05.
GOALS6 = ((0, 0), (1, 2), (2, 3), (3, 4), (0, 4), (3, 0))
#: Six other goals: runs on GOALS6 and on these share no goal.
OTHER6 = ((0, 1), (1, 1), (2, 2), (3, 3), (1, 4), (2, 0))


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


def _edit_json(path: Path, edit) -> None:
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


def _cell(comparison, method: str, run: str, metric: str):
    table = comparison.table.set_index(["method", "run", "metric"])
    return table.loc[(method, run, metric)]


def test_changes_and_time_ratios_are_against_the_first_run(runs) -> None:
    comparison = compare_runs(runs)
    ae = _cell(comparison, "warping", "b", "mean_ae_deg")
    assert (ae["reference"], ae["value"], ae["change"]) == pytest.approx((10.0, 40.0, 30.0))
    ahc = _cell(comparison, "warping", "b", "ahc")
    assert ahc["change"] == pytest.approx(math.cos(math.radians(40)) - math.cos(math.radians(10)))
    assert _cell(comparison, "warping", "b", "home_ms")["change"] == pytest.approx(3.0)
    assert _cell(comparison, "warping", "b", "describe_ms")["change"] == pytest.approx(0.25)
    assert set(comparison.table["test"]) == {"paired", "ratio"}
    # only cells of both runs are compared; the others are said to be missing
    assert set(comparison.table["method"]) == {"warping"}
    assert "b: no results for old under a-a" in comparison.warnings
    assert "a: no results for new under a-a" in comparison.warnings


def test_a_known_difference_is_significant_and_identical_runs_give_zero(tmp_path: Path) -> None:
    ten, forty = FakeMethod("m", 10.0), FakeMethod("m", 40.0)
    a = write_fake_run(tmp_path / "a", [ten], GOALS6)
    same = write_fake_run(tmp_path / "same", [ten], GOALS6)
    worse = write_fake_run(tmp_path / "worse", [forty], GOALS6)
    comparison = compare_runs([a, same, worse])
    diff = _cell(comparison, "m", "worse", "mean_ae_deg")
    assert diff["test"] == "paired" and diff["change"] == pytest.approx(30.0)
    assert diff["lo"] == pytest.approx(30.0) and diff["hi"] == pytest.approx(30.0)
    assert diff["p"] == pytest.approx(2 / 2**6)  # every goal worse: the exact test's floor
    for metric in ("mean_ae_deg", "ahc", "rr"):
        zero = _cell(comparison, "m", "same", metric)
        assert (zero["change"], zero["lo"], zero["hi"]) == (0.0, 0.0, 0.0)
        assert zero["p"] == 1.0 and zero["p_holm"] == 1.0
    # the numbers are seeded by the cell: a second comparison is identical
    again = compare_runs([a, same, worse])
    assert to_csv(again.view()) == to_csv(comparison.view())


def test_runs_sharing_some_pairs_are_paired_on_those_and_say_so(tmp_path: Path) -> None:
    a = write_fake_run(tmp_path / "a", [FakeMethod("m", 10.0)], GOALS6)
    b = write_fake_run(tmp_path / "b", [FakeMethod("m", 40.0)], GOALS6)
    next((b / "jobs").iterdir()).unlink()  # one goal's 19 pairs are missing in b
    comparison = compare_runs([a, b])
    diff = _cell(comparison, "m", "b", "mean_ae_deg")
    assert diff["test"] == "paired" and (diff["n_goals_ref"], diff["n_goals"]) == (5, 5)
    assert diff["p"] == pytest.approx(2 / 2**5)
    assert "b: m under a-a compared on the 95 pairs it shares with a (of 95; 114 in a)" in (
        comparison.warnings
    )


def test_runs_on_other_goals_are_compared_unpaired(tmp_path: Path) -> None:
    a = write_fake_run(tmp_path / "a", [FakeMethod("m", 10.0)], GOALS6)
    b = write_fake_run(tmp_path / "b", [FakeMethod("m", 40.0)], OTHER6)
    diff = _cell(compare_runs([a, b]), "m", "b", "mean_ae_deg")
    assert diff["test"] == "unpaired" and diff["change"] == pytest.approx(30.0)
    assert (diff["lo"], diff["hi"]) == pytest.approx((30.0, 30.0))
    # of the comb(12, 6) deals of goals only the observed one and its mirror are as extreme
    assert diff["p"] == pytest.approx(2 / math.comb(12, 6))


def test_differences_list_changed_parameters_and_environment(runs) -> None:
    a, b = runs
    _edit_json(a / "config.resolved.json", lambda c: c["methods"][0]["params"].update(ratio=0.8))
    _edit_json(b / "config.resolved.json", lambda c: c["methods"][0]["params"].update(ratio=0.7))
    _edit_json(b / "environment.json", lambda e: e.update(git={"commit": "abc", "dirty": False}))
    differences = compare_runs(runs).differences
    assert "b: config methods[0].params.ratio: 0.8 -> 0.7" in differences
    assert 'b: config methods[1].label: "old" -> "new"' in differences
    assert 'b: environment git.commit: (absent) -> "abc"' in differences
    assert not any("host" in d or "started" in d for d in differences)  # not result-relevant


def test_labels_are_folder_names_told_apart_by_their_parents(tmp_path: Path) -> None:
    folders = [tmp_path / "x" / "seed1" / "run", tmp_path / "y" / "seed1" / "run", tmp_path / "z"]
    assert run_labels(folders) == ["x/seed1/run", "y/seed1/run", "z"]
    assert run_labels(folders, ["A", "B", "C"]) == ["A", "B", "C"]
    with pytest.raises(ConfigError, match="2 label"):
        run_labels(folders, ["A", "B"])
    with pytest.raises(ConfigError, match="names two runs"):
        run_labels([folders[0], folders[0]])


@pytest.mark.parametrize(
    ("text", "parsed"),
    [("ahc < -0.02", ("ahc", "<", -0.02)), ("rr<=-1e-2", ("rr", "<=", -0.01)),
     (" mean_ae_deg >2 ", ("mean_ae_deg", ">", 2.0)), ("home_ms >= 1.5", ("home_ms", ">=", 1.5))],
)  # fmt: skip
def test_thresholds_are_read_by_a_small_grammar(text: str, parsed: tuple) -> None:
    threshold = Threshold.parse(text)
    assert (threshold.metric, threshold.op, threshold.limit) == parsed


@pytest.mark.parametrize(
    "text", ["ahc <", "__import__('os')", "ahc == 1", "speed < 1", "ahc < 1 or 1", "ahc < 0x1"]
)
def test_bad_thresholds_are_config_errors(text: str) -> None:
    with pytest.raises(ConfigError, match="expected METRIC OP NUMBER"):
        Threshold.parse(text)


def test_cli_prints_differences_first_then_the_table(runs) -> None:
    result = CliRunner().invoke(main, ["compare", *map(str, runs)])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("Differences from a:\n  b: config methods[1].label")
    assert "| a-a         | warping  | b     | mean_ae_deg |" in result.stdout
    assert "homebench: warning: b: no results for old under a-a" in result.stderr
    result = CliRunner().invoke(main, ["compare", *map(str, runs), "--label", "A", "--label", "B"])
    assert "Differences from A:" in result.stdout and "| B     |" in result.stdout


def test_cli_fail_if_exits_3_on_a_regression_and_0_otherwise(runs) -> None:
    args = ["compare", *map(str, runs), "--fail-if"]
    failed = CliRunner().invoke(main, [*args, "ahc < -0.02", "--fail-if", "rr < -0.5"])
    assert failed.exit_code == 3, failed.output
    assert failed.stderr.splitlines()[-1] == (
        "homebench: check failed: b: ahc change -0.2188 under a-a for warping "
        "(--fail-if 'ahc < -0.02')"
    )
    passed = CliRunner().invoke(main, [*args, "ahc < -0.5", "--fail-if", "home_ms > 3.5"])
    assert passed.exit_code == 0, passed.output
    assert "all 2 --fail-if threshold(s) passed" in passed.stdout
    for bad in ("ahc <", "__import__('os')"):
        result = CliRunner().invoke(main, [*args, bad])
        assert result.exit_code == 2 and len(result.stderr.splitlines()) == 1
        assert "expected METRIC OP NUMBER" in result.stderr


def test_cli_out_writes_exactly_that_file(runs, tmp_path: Path) -> None:
    folder = tmp_path / "out"
    result = CliRunner().invoke(main, ["compare", *map(str, runs), "--out", str(folder / "x.md")])
    assert result.exit_code == 0, result.output
    assert sorted(folder.iterdir()) == [folder / "x.md"]
    assert (folder / "x.md").read_text().startswith("**Runs compared with a")
    result = CliRunner().invoke(main, ["compare", *map(str, runs), "--out", str(folder / "x.txt")])
    assert result.exit_code == 2 and "must end in .csv, .md or .tex" in result.stderr
    assert sorted(folder.iterdir()) == [folder / "x.md"]


def test_runs_that_cannot_be_compared_are_one_line_errors(runs, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="at least two"):
        compare_runs([runs[0]])
    with pytest.raises(DataError, match="nowhere: no such run folder"):
        compare_runs([runs[0], tmp_path / "nowhere"])
    route = tmp_path / "route"
    route.mkdir()
    (route / "config.resolved.json").write_text(json.dumps({"kind": "route"}))
    (route / "environment.json").write_text("{}")
    empty = write_fake_run(tmp_path / "empty", [FakeMethod("m")])
    for job in (empty / "jobs").iterdir():
        job.unlink()
    for other, message in ((route, "a route run; only grid runs"), (empty, "no job results")):
        result = CliRunner().invoke(main, ["compare", str(runs[0]), str(other)])
        assert result.exit_code == 2 and len(result.stderr.splitlines()) == 1
        assert f"{other}: {message}" in result.stderr


def test_runs_on_other_databases_are_compared_unpaired_and_say_so(tmp_path: Path) -> None:
    """The same grid positions of two worlds are not the same pairs: a paired test on them
    would be wrong, whatever the grid indices say."""
    a = write_fake_run(tmp_path / "a", [FakeMethod("m", 10.0)], GOALS6, world="one")
    b = write_fake_run(tmp_path / "b", [FakeMethod("m", 40.0)], GOALS6, world="two")
    comparison = compare_runs([a, b])
    diff = _cell(comparison, "m", "b", "mean_ae_deg")
    assert diff["test"] == "unpaired" and diff["change"] == pytest.approx(30.0)
    assert diff["p"] == pytest.approx(2 / math.comb(12, 6))
    assert any(
        w.startswith("b: m under a-a: other databases than a's (") and "compared unpaired" in w
        for w in comparison.warnings
    ), comparison.warnings
    same = write_fake_run(tmp_path / "c", [FakeMethod("m", 40.0)], GOALS6, world="one")
    assert _cell(compare_runs([a, same]), "m", "c", "mean_ae_deg")["test"] == "paired"


def test_a_method_without_home_directions_has_only_time_ratios(tmp_path: Path) -> None:
    compass = FakeMethod("compass", 5.0, gives_direction=False)
    a = write_fake_run(tmp_path / "a", [FakeMethod("m", 10.0), compass], GOALS6)
    b = write_fake_run(tmp_path / "b", [FakeMethod("m", 40.0), compass], GOALS6)
    table = compare_runs([a, b]).table
    assert set(table.loc[table["method"] == "compass", "test"]) == {"ratio"}
    assert set(table.loc[table["method"] == "m", "test"]) == {"paired", "ratio"}
