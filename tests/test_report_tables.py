"""Report tables: rounding, units, the three writers, and numbers equal to the job files'."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_report_runs import GRID, FakeMethod, write_fake_run

from homebench.config import MetricsConfig
from homebench.evaluation.results import build_tables
from homebench.report.tables import (
    Digits,
    report_views,
    to_csv,
    to_latex,
    to_markdown,
    write_views,
)

METHODS = [
    FakeMethod("perfect", 0.0),
    FakeMethod("reversed", 180.0),
    FakeMethod("holes_10", 10.0, frozenset({(0, 0), (3, 4), (2, 0)}), home_ms=1234.5),
]


@pytest.fixture
def views(tmp_path: Path) -> dict[str, object]:
    run = write_fake_run(tmp_path / "run", METHODS, conditions=("a-a", "a-b"))
    return {v.name: v for v in report_views(build_tables(run, MetricsConfig()))}


@pytest.mark.parametrize(
    ("digits", "value", "text", "rounded"),
    [
        (Digits(2), 3.14159, "3.14", 3.14),
        (Digits(0), 38.0, "38", 38.0),
        (Digits(3), -0.0001, "0.000", 0.0),  # no "-0.000"
        (Digits(significant=3), 1234.5, "1230", 1230.0),
        (Digits(significant=3), 0.012345, "0.0123", 0.0123),
        (Digits(significant=3), 16.06, "16.1", 16.1),
        (Digits(2), math.nan, "--", math.nan),
    ],
)
def test_digits_round_and_print(digits: Digits, value: float, text: str, rounded: float) -> None:
    assert digits.text(value) == text
    assert digits.round(value) == rounded or (math.isnan(rounded) and math.isnan(value))


def _job_pairs(run_dir: Path) -> pd.DataFrame:
    """The pairs straight from the job files, without homebench's loader."""
    frames = []
    for path in sorted((run_dir / "jobs").glob("*.json")):
        record = json.loads(path.read_text())
        frame = pd.DataFrame(record["rows"])
        frame["condition"], frame["method"] = record["condition"], record["method"]
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def test_summary_numbers_equal_the_job_files(tmp_path: Path) -> None:
    run = write_fake_run(tmp_path / "run", METHODS, conditions=("a-a", "a-b"))
    write_views(report_views(build_tables(run, MetricsConfig())), tmp_path / "tables")
    table = pd.read_csv(tmp_path / "tables" / "summary.csv")
    assert len(table) == 2 * 3
    pairs = _job_pairs(run)
    for (condition, method), group in pairs.groupby(["condition", "method"]):
        row = table[(table["condition"] == condition) & (table["method"] == method)].iloc[0]
        ae = group["ae"].astype(float)
        assert row["pairs"] == len(group)
        assert row["no estimate [%]"] == round(100 * ae.isna().mean(), 1)
        assert row["mean AE [deg]"] == round(np.degrees(ae.mean()), 2)
        assert row["median AE [deg]"] == round(np.degrees(ae.median()), 2)
        assert row["AHC"] == round(math.cos(ae.mean()), 3)
        assert row["home [ms/pair]"] == float(f"{group['home_ms'].mean():.3g}")
    by_method = table.set_index(["condition", "method"])
    # known return ratios: every start of the perfect field arrives; of the reversed field
    # only the goal itself (1 of the 20 positions)
    assert (by_method.xs("perfect", level="method")["RR"] == 1.0).all()
    assert (by_method.xs("reversed", level="method")["RR"] == round(1 / GRID.size, 3)).all()
    assert (by_method.xs("reversed", level="method")["AHC"] == -1.0).all()
    assert by_method.loc[("a-a", "holes_10"), "mean AE [deg]"] == 10.0


def test_rr_by_goal_is_one_row_per_goal_and_one_column_per_method(views: dict) -> None:
    frame = views["rr_by_goal"].frame
    assert list(frame.columns) == ["condition", "goal (i, j)", "holes_10", "perfect", "reversed"]
    assert frame["goal (i, j)"].tolist() == ["(1, 2)", "(2, 3)"] * 2
    assert (frame["perfect"] == 1.0).all()
    assert (frame["reversed"] == 0.05).all()


def test_ahc_by_distance_has_only_bins_with_pairs(views: dict) -> None:
    frame = views["ahc_by_distance"].frame
    assert "all" not in frame["distance [cm]"].astype(str).tolist()
    # the 4 x 5 grid 0.3 m apart: nearest-bin distances from goals (1, 2) and (2, 3)
    assert frame["distance [cm]"].max() <= 150 and frame["distance [cm]"].min() == 30
    assert (frame["perfect"] == 1.0).all() and (frame["reversed"] == -1.0).all()
    holes = frame.set_index("distance [cm]")["holes_10"]
    # the only pair 120 cm apart, (0, 0) to goal (2, 3), has no estimate: no AHC there
    assert holes.loc[120].isna().all()
    assert np.allclose(holes.drop(index=120), round(math.cos(math.radians(10)), 3))


def test_writers_show_units_rounding_and_missing_values(views: dict) -> None:
    summary = views["summary"]
    csv = to_csv(summary)
    assert csv.splitlines()[0] == (
        "condition,method,pairs,no estimate [%],mean AE [deg],median AE [deg],AHC,RR,"
        "catchment,describe [ms/image],home [ms/pair]"
    )
    assert ",1230.0" in csv  # home time to 3 significant digits
    markdown = to_markdown(summary)
    assert "| holes_10 " in markdown and "0.985" in markdown and "1230" in markdown
    latex = to_latex(summary)
    for rule in ("\\toprule", "\\midrule", "\\bottomrule"):
        assert latex.count(rule) == 1
    assert "holes\\_10" in latex and "no estimate [\\%]" in latex
    assert "\\caption{" in latex
    # a return ratio that cannot be computed prints as "--", never "nan"
    view = views["rr_by_goal"]
    view.frame.loc[0, "perfect"] = math.nan
    assert "--" in to_markdown(view) and "nan" not in to_markdown(view).lower()
    assert "--" in to_latex(view)


def test_write_views_writes_three_files_per_table(views: dict, tmp_path: Path) -> None:
    written = write_views(list(views.values()), tmp_path / "out")
    assert sorted(p.name for p in written) == sorted(
        f"{name}.{suffix}" for name in views for suffix in ("csv", "md", "tex")
    )
    assert all(p.stat().st_size > 100 for p in written)
