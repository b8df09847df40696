"""Report tables: rounding, intervals, config order, significance marks, the writers (CSV, MD,
LaTeX, console, PDF pages) and the run folder's tables, on synthetic runs whose answers are
known."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import arena_config, run_config
from matplotlib.backends.backend_agg import FigureCanvasAgg
from test_report_runs import GRID, FakeMethod, write_fake_run
from test_results_uncertainty import synthetic_pairs
from test_results_uncertainty import tables as synthetic_tables

from homebench.analysis.comparisons import COLUMNS
from homebench.analysis.tables import RunTables, method_comparisons
from homebench.config import MetricsConfig, ReturnRatioConfig
from homebench.evaluation.results import ANGLE_COLUMNS, build_tables, write_tables
from homebench.report.pages import TABLE_FONT_SIZE, TABLE_ROWS, table_pages
from homebench.report.run_data import load_run
from homebench.report.tables import (
    CONSOLE_WIDTH,
    FIXED3,
    MISSING_TEXT,
    P_VALUE,
    Digits,
    RowOrder,
    band_view,
    console_summary,
    few_goals_note,
    headline_view,
    make_view,
    report_views,
    run_order,
    summary_view,
    to_csv,
    to_latex,
    to_markdown,
    to_text,
    write_views,
)

METHODS = [
    FakeMethod("perfect", 0.0),
    FakeMethod("reversed", 180.0),
    FakeMethod("holes_10", 10.0, frozenset({(0, 0), (3, 4), (2, 0)}), home_ms=1234.5),
]
#: The fake run's config order: neither alphabetical nor reversed.
CONDITIONS = ("a-b", "a-a")
ORDER = RowOrder(CONDITIONS, tuple(m.label for m in METHODS))


@pytest.fixture
def views(tmp_path: Path) -> dict[str, object]:
    run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS)
    return {v.name: v for v in report_views(build_tables(run, MetricsConfig()), ORDER)}


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
        (P_VALUE, 0.0123, "0.012", 0.012),
        (P_VALUE, 2.4e-36, "<0.001", 2.4e-36),  # the CSV keeps the number
        (P_VALUE, 1.0, "1.0", 1.0),
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
    run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS)
    write_views(report_views(build_tables(run, MetricsConfig()), ORDER), tmp_path / "tables")
    table = pd.read_csv(tmp_path / "tables" / "summary.csv")
    assert len(table) == 2 * 3
    pairs = _job_pairs(run)
    for (condition, method), group in pairs.groupby(["condition", "method"]):
        row = table[(table["condition"] == condition) & (table["method"] == method)].iloc[0]
        ae = group["ae"].astype(float)
        assert row["pairs"] == len(group) and row["n goals"] == 2
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
    # every goal of the fixed offsets has the same AE: the interval has no width
    assert by_method.loc[("a-a", "holes_10"), "mean AE [deg] lo"] == 10.0


# --------------------------------------------------------------------------- intervals


def _summary_row(**metrics: float) -> pd.DataFrame:
    """A one-row summary table of condition "a-a", method "m" with ``metrics``."""
    return pd.DataFrame([{"condition": "a-a", "method": "m", "pairs": 190, "n_goals": 10,
                          **metrics}])  # fmt: skip


def test_an_interval_cell_reads_estimate_lo_hi_and_the_csv_keeps_the_numbers() -> None:
    summary = _summary_row(ahc=0.97312, ahc_lo=0.95149, ahc_hi=0.98777, median_ae_deg=3.14159,
                           no_estimate_share=0.25, no_estimate_share_lo=0.125,
                           no_estimate_share_hi=0.5)  # fmt: skip
    view = summary_view(summary, RowOrder(), pd.DataFrame(columns=COLUMNS))
    shown = view.text_frame().iloc[0]
    assert shown["AHC"] == "0.973 [0.951, 0.988]"
    assert shown["no estimate [%]"] == "25.0 [12.5, 50.0]"
    assert shown["median AE [deg]"] == "3.14"  # no bounds: the estimate alone
    assert shown["n goals"] == "10" and shown["pairs"] == "190"
    assert "AHC lo" not in shown.index
    header, row = to_csv(view).splitlines()
    assert header == (
        "condition,method,n goals,pairs,no estimate [%],no estimate [%] lo,no estimate [%] hi,"
        "median AE [deg],AHC,AHC lo,AHC hi"
    )
    assert row == "a-a,m,10,190,25.0,12.5,50.0,3.14,0.973,0.951,0.988"


def test_a_metric_without_bounds_shows_its_estimate_alone() -> None:
    summary = _summary_row(ahc=0.9, ahc_lo=math.nan, ahc_hi=math.nan, rr=math.nan,
                           rr_lo=math.nan, rr_hi=math.nan)  # fmt: skip
    shown = summary_view(summary, RowOrder(), pd.DataFrame(columns=COLUMNS)).text_frame()
    assert shown.loc[0, "AHC"] == "0.900" and shown.loc[0, "RR"] == "--"


# --------------------------------------------------------------------------- config order


def test_rows_and_method_columns_follow_the_config_order(views: dict) -> None:
    summary = views["summary"].frame
    assert list(zip(summary["condition"], summary["method"], strict=True)) == [
        (c, m.label) for c in CONDITIONS for m in METHODS
    ]
    rr = views["rr_by_goal"].frame
    ended = [f"{m} ended on no est. [%]" for m in ("perfect", "reversed", "holes_10")]
    assert list(rr.columns) == ["condition", "goal (i, j)", "perfect", "reversed", "holes_10",
                                *ended]  # fmt: skip
    assert rr["condition"].tolist() == ["a-b", "a-b", "a-a", "a-a"]
    assert rr["goal (i, j)"].tolist() == ["(1, 2)", "(2, 3)"] * 2
    ahc = views["ahc_by_distance"]
    assert ahc.text_frame().columns.tolist()[2:] == ["perfect", "reversed", "holes_10"]
    assert ahc.frame["condition"].iloc[0] == "a-b"
    # A is the method listed first; B - A turns sign with it
    comparisons = views["comparisons"].frame
    assert comparisons[["condition", "metric", "A", "B"]].head(4).values.tolist() == [
        ["a-b", "mean AE [deg]", "perfect", "reversed"],
        ["a-b", "mean AE [deg]", "perfect", "holes_10"],
        ["a-b", "mean AE [deg]", "reversed", "holes_10"],
        ["a-b", "AHC", "perfect", "reversed"],
    ]
    # AE counted as 90 deg where holes_10 has no estimate (3 positions x 2 goals of 38 pairs)
    assert comparisons.loc[1, "B - A"] == round((32 * 10 + 6 * 90) / 38, 3)
    assert comparisons.loc[2, "B - A"] == round((32 * 10 + 6 * 90) / 38 - 180, 3)


def test_rr_table_gives_the_share_of_walks_ended_by_an_abstention(tmp_path: Path) -> None:
    """holes_10 has no estimate at (0, 0), (3, 4), (2, 0): the walks from there end at once,
    in failure by default, as arrivals next to the goal with no_estimate: arrived; the notes
    say which reading the run used and the radius's unit."""
    run = write_fake_run(tmp_path / "run", METHODS, conditions=("a-a",))
    found = {}
    for reading in ("fail", "arrived"):
        metrics = MetricsConfig(return_ratio={"no_estimate": reading})
        views = report_views(build_tables(run, metrics), ORDER)
        found[reading] = next(v for v in views if v.name == "rr_by_goal")
    strict, lenient = found["fail"], found["arrived"]
    share = strict.frame["holes_10 ended on no est. [%]"]
    assert (share >= 100 * 3 / GRID.size).all()
    assert (strict.frame["perfect ended on no est. [%]"] == 0).all()
    pd.testing.assert_series_equal(share, lenient.frame["holes_10 ended on no est. [%]"])
    # goal (2, 3) neighbours (3, 4): that walk arrives
    assert lenient.frame.loc[1, "holes_10"] > strict.frame.loc[1, "holes_10"]
    notes = " ".join(strict.notes)
    assert "0.5 grid units" in notes and "no_estimate: fail" in notes
    assert "no_estimate: arrived" in " ".join(lenient.notes)


def test_intervals_on_fewer_than_five_goals_carry_a_visible_note(views: dict) -> None:
    """The fake run has 2 goals: every table that draws intervals says so; 10 goals: none."""
    for name in ("headline", "bands", "summary", "ahc_by_distance", "comparisons"):
        assert any("rest on 2 goals" in note for note in views[name].notes), name
        assert "rest on 2 goals" in to_markdown(views[name])
    assert not any("goals, fewer than" in note for note in views["rr_by_goal"].notes)
    assert few_goals_note([1, 1]) == ""  # a single goal has no interval at all
    assert few_goals_note([5, 30]) == ""
    assert "rest on 2 to 4 goals" in few_goals_note([2, 4, 12, math.nan])
    ten = synthetic_tables(synthetic_pairs({"a": (0.0, 3.0)}))
    headline = headline_view(ten["summary"], RowOrder(), pd.DataFrame(columns=COLUMNS))
    assert not any("fewer than" in note for note in headline.notes)


def test_headline_and_console_say_when_rr_counts_an_abstention_as_arrival() -> None:
    summary = synthetic_tables(synthetic_pairs({"a": (0.0, 3.0)}))["summary"]
    none = pd.DataFrame(columns=COLUMNS)
    arrived = ReturnRatioConfig(no_estimate="arrived")
    assert "no_estimate" not in " ".join(headline_view(summary, RowOrder(), none).notes)
    said = " ".join(headline_view(summary, RowOrder(), none, rr=arrived).notes)
    assert "goal's 8 grid neighbours" in said and "no_estimate: arrived" in said
    assert "no_estimate: arrived" in " ".join(
        summary_view(summary, RowOrder(), none, rr=arrived).notes
    )
    assert "no_estimate:" in console_summary(summary, RowOrder(), none, rr=arrived)


def test_labels_the_order_does_not_list_come_last_sorted() -> None:
    order = RowOrder(("b-b",), ("z",))
    frame = pd.DataFrame(
        {"condition": ["a-a", "c-c", "b-b", "b-b"], "method": ["x", "z", "y", "z"]}
    )
    assert order.sort(frame).values.tolist() == [["b-b", "z"], ["b-b", "y"], ["a-a", "x"],
                                                 ["c-c", "z"]]  # fmt: skip
    assert order.methods_of(["y", "z", "x", "y"]) == ["z", "x", "y"]


def test_the_run_order_is_the_config_order(tmp_path: Path) -> None:
    methods = [FakeMethod("w", 5.0), FakeMethod("sift", 10.0)]
    run = write_fake_run(tmp_path / "run", methods, conditions=("z-z", "a-a", "m-m"))
    assert run_order(load_run(run)) == RowOrder(("z-z", "a-a", "m-m"), ("w", "sift"))


# --------------------------------------------------------------------------- marks


def _run_tables(pairs: pd.DataFrame) -> RunTables:
    made = synthetic_tables(pairs)
    return RunTables(pairs, made["summary"], made["goals"], made["ahc"], (),
                     rr_starts=made["rr_starts"])  # fmt: skip


def _marked(pairs: pd.DataFrame, order: RowOrder) -> set[tuple[str, str]]:
    """(method, column) of the summary's marked cells."""
    tables = _run_tables(pairs)
    view = summary_view(tables.summary, order, method_comparisons(tables))
    return {(view.frame.loc[row, "method"], column) for row, column in view.marked}


def test_the_significantly_best_method_is_marked() -> None:
    """10 goals, "good" 15 deg better on every one: its AE and AHC cells are marked (sign-flip
    p = 2 / 2**10 before Holm); the return ratios do not differ, so no RR cell is."""
    pairs = synthetic_pairs({"good": (0.0, 3.0), "bad": (15.0, 3.0), "bad_twin": (15.0, 3.0)})
    assert _marked(pairs, RowOrder(("a-b",), ("bad", "good", "bad_twin"))) == {
        ("good", "mean AE [deg]"),
        ("good", "AHC"),
        ("good", "AHC (no estimate = 90 deg)"),
    }


def test_two_equal_methods_are_not_marked() -> None:
    pairs = synthetic_pairs({"a": (0.0, 3.0)})
    twins = pd.concat([pairs, pairs.assign(method="a_copy")], ignore_index=True)
    assert _marked(twins, RowOrder()) == set()


def test_a_method_that_abstains_is_not_marked_for_its_mean_ae() -> None:
    """Method "abstains" has the lower AE on the pairs it answers but none on 60 % of them;
    compared with a missing estimate as 90 deg it is significantly worse, so none of its
    cells is marked; "steady" is marked where its value is the best: AHC with a missing
    estimate as 90 deg and RR (a field with holes leads few starts home)."""
    abstains = synthetic_pairs({"abstains": (0.0, 3.0)}, missing=0.6, seed=1)
    steady = synthetic_pairs({"steady": (10.0, 3.0)}, missing=0.0, seed=2)
    pairs = pd.concat([abstains, steady], ignore_index=True)
    assert _marked(pairs, RowOrder()) == {
        ("steady", "AHC (no estimate = 90 deg)"),
        ("steady", "RR"),
    }


def test_every_writer_shows_the_marks_and_says_what_they_mean() -> None:
    pairs = synthetic_pairs({"good": (0.0, 3.0), "bad": (15.0, 3.0)})
    tables = _run_tables(pairs)
    view = summary_view(tables.summary, RowOrder(), method_comparisons(tables))
    good = view.text_frame().set_index("method").loc["good", "mean AE [deg]"]
    bad = view.text_frame().set_index("method").loc["bad", "mean AE [deg]"]
    assert f"**{good}**" in to_markdown(view) and f"**{bad}**" not in to_markdown(view)
    assert "**bold**: the best value of its condition" in to_markdown(view)
    assert f"\\bfseries {good}" in to_latex(view) and f"\\bfseries {bad}" not in to_latex(view)
    assert "Bold: the best value" in to_latex(view)
    console = to_text(view)
    assert f"{good}*" in console and f"{bad} " in console and f"{bad}*" not in console
    notes = [line for line in console.splitlines() if not line.startswith(" ")]
    assert notes[-3].startswith("*: the best value of its condition")
    assert "sign-flip test (p < 0.05, Holm-adjusted" in " ".join(console.split())
    (page,) = table_pages(view)
    (table,) = page.axes[0].tables
    weights = {cell.get_text().get_text(): cell.get_text().get_fontweight()
               for (row, _), cell in table.get_celld().items() if row > 0}  # fmt: skip
    assert weights[good] == "bold" and weights[bad] == "normal"
    assert any("Bold: the best value" in text.get_text() for text in page.texts)


# --------------------------------------------------------------------------- writers


def test_writers_show_units_rounding_and_missing_values(views: dict) -> None:
    summary = views["summary"]
    csv = to_csv(summary)
    assert csv.splitlines()[0] == (
        "condition,method,n goals,pairs,no estimate [%],no estimate [%] lo,no estimate [%] hi,"
        "mean AE [deg],mean AE [deg] lo,mean AE [deg] hi,median AE [deg],"
        "rotation error [deg],rotation error [deg] lo,rotation error [deg] hi,"
        "rotation flips [%],rotation flips [%] lo,rotation flips [%] hi,AHC,AHC lo,AHC hi,"
        "AHC (no estimate = 90 deg),AHC (no estimate = 90 deg) lo,"
        "AHC (no estimate = 90 deg) hi,RR,RR lo,RR hi,catchment,catchment lo,catchment hi,"
        "describe [ms/image],home [ms/pair]"
    )
    assert ",1230.0" in csv  # home time to 3 significant digits
    markdown = to_markdown(summary)
    assert "| holes_10 " in markdown and "0.985 [0.985, 0.985]" in markdown
    assert "1230" in markdown
    latex = to_latex(summary)
    for rule in ("\\toprule", "\\midrule", "\\bottomrule"):
        assert latex.count(rule) == 1
    assert "holes\\_10" in latex and "{no estimate [\\%]}" in latex
    assert "\\caption{" in latex
    # a return ratio that cannot be computed prints as "--", never "nan"
    view = views["rr_by_goal"]
    view.frame.loc[0, "perfect"] = math.nan
    assert "--" in to_markdown(view) and "nan" not in to_markdown(view).lower()
    assert "{--}" in to_latex(view)  # siunitx reads a braced cell as text


def _check_latex(latex: str) -> None:
    """Braces balance (escaped ones aside) and environments nest."""
    depth = 0
    for char in re.sub(r"\\[{}]", "", latex):
        depth += {"{": 1, "}": -1}.get(char, 0)
        assert depth >= 0
    assert depth == 0
    stack = []
    for kind, name in re.findall(r"\\(begin|end)\{(\w+)\}", latex):
        if kind == "begin":
            stack.append(name)
        else:
            assert stack.pop() == name
    assert stack == []


def _wide_view(rows: int, columns: int = 12) -> object:
    """A view of ``rows`` rows: a method label, a text column and ``columns - 2`` interval
    columns with long numbers; row 3's first interval cell marked."""
    frame = pd.DataFrame({"method": [f"my_method_{k}" for k in range(rows)],
                          "condition": "original-arboreal"})  # fmt: skip
    bounds = {}
    for k in range(columns - 2):
        header = f"metric number {k} [deg/s]"
        frame[header] = 123.456 + np.arange(rows)
        frame[f"{header} lo"], frame[f"{header} hi"] = frame[header] - 100, frame[header] + 100
        bounds[header] = (f"{header} lo", f"{header} hi")
    digits = {header: FIXED3 for header in bounds}
    return make_view("wide", "A wide table", frame, digits, bounds,
                     frozenset({(3, "metric number 0 [deg/s]")}), "marked")  # fmt: skip


def test_latex_is_valid_with_siunitx_and_escapes() -> None:
    view = _wide_view(5)
    latex = to_latex(view)
    _check_latex(latex)
    assert "\\begin{table}[htbp]" in latex and "longtable" not in latex
    assert "\\begin{tabular}{ll" + "r" * 10 + "}" in latex
    assert "my\\_method\\_3 & original-arboreal & \\bfseries 126.456 [26.456, 226.456]" in latex
    assert "{metric number 0 [deg/s]}" in latex  # siunitx: headers braced
    summary = to_latex(summary_view(_summary_row(home_ms=2.5), RowOrder(),
                                    pd.DataFrame(columns=COLUMNS)))  # fmt: skip
    _check_latex(summary)
    assert "\\begin{tabular}{llSSS}" in summary  # single numbers: siunitx S columns


def test_a_long_latex_table_is_a_longtable() -> None:
    latex = to_latex(_wide_view(41))
    _check_latex(latex)
    assert latex.startswith("\\begin{longtable}") and "\\begin{table}" not in latex
    assert latex.count("\\endhead") == 1 and "my\\_method\\_40" in latex


def test_pdf_table_pages_keep_a_wide_long_table_on_the_page() -> None:
    view = _wide_view(40)
    pages = table_pages(view)
    assert len(pages) == math.ceil(40 / TABLE_ROWS)
    for page in pages:
        renderer = FigureCanvasAgg(page).get_renderer()
        page.draw(renderer)
        (table,) = page.axes[0].tables
        box = table.get_window_extent(renderer)
        assert box.x0 >= 0 and box.y0 >= 0, box
        assert box.x1 <= page.bbox.width and box.y1 <= page.bbox.height, box
    (table,) = pages[0].axes[0].tables
    assert table.get_celld()[(4, 2)].get_text().get_fontweight() == "bold"  # row 3, marked
    assert table.get_celld()[(5, 2)].get_text().get_fontweight() == "normal"


def test_write_views_writes_three_files_per_table(views: dict, tmp_path: Path) -> None:
    assert list(views) == [
        "headline", "bands", "summary", "rr_by_goal", "ahc_by_distance", "comparisons"
    ]  # fmt: skip
    written = write_views(list(views.values()), tmp_path / "out")
    assert sorted(p.name for p in written) == sorted(
        f"{name}.{suffix}" for name in views for suffix in ("csv", "md", "tex")
    )
    assert all(p.stat().st_size > 100 for p in written)


def test_comparisons_view_prints_differences_and_p_values(views: dict) -> None:
    view = views["comparisons"]
    header = to_csv(view).splitlines()[0]
    assert header == (
        "condition,metric,A,B,B - A,B - A lo,B - A hi,p goal (Holm),p pair test (Holm),n goals"
    )
    shown = view.text_frame()
    assert len(shown) == 2 * 3 * 3  # conditions x method pairs x (AE, AHC, RR)
    assert shown.loc[0, "B - A"] == "180.000 [180.000, 180.000]"
    assert shown.loc[0, "n goals"] == "2"
    assert (shown["p goal (Holm)"] == "1.0").all()  # two goals: p is at least 0.5


def _outside_math(latex: str) -> str:
    """``latex`` without its inline math ($...$; an escaped \\$ is text)."""
    return re.sub(r"(?<!\\)\$.*?(?<!\\)\$", "", latex)


def test_latex_writes_less_and_greater_than_in_math_mode(views: dict) -> None:
    """OT1, LaTeX's default font encoding, prints a text-mode < as an inverted ! (and > as an
    inverted ?): every < and > of a title, note, header or cell is in math mode."""
    frame = pd.DataFrame({"method": ["a<b", "c>d"], "p": [2.4e-36, 0.5]})
    view = make_view("angles", "Title with p < 0.05 and AHC > 0", frame, {"p": P_VALUE},
                     notes=("note: x < y > z",))  # fmt: skip
    texts = [to_latex(view), *(to_latex(v) for v in views.values())]
    for latex in texts:
        _check_latex(latex)
        outside = _outside_math(latex)
        assert "<" not in outside and ">" not in outside, outside
    latex = texts[0]
    assert "{$<$0.001}" in latex  # a p-value below the printed precision: braced for siunitx
    assert "p $<$ 0.05" in latex and "AHC $>$ 0" in latex and "a$<$b" in latex
    assert "p $<$ 0.05" in to_latex(views["headline"])  # the significance note


# --------------------------------------------------------------------------- headline


#: Labels as long as the built-in methods' and the generated databases' conditions.
LONG_METHODS = ["warping", "min-warping", "warping-2d", "fourier-warping", "sift", "klt-sector",
                "mfdid", "did", "alv", "snapshot", "block-matching", "visual-compass"]  # fmt: skip
LONG_CONDITIONS = ["original-original", "original-arboreal", "original-chairs",
                   "original-day", "original-twilight"]  # fmt: skip


def _long_summary() -> pd.DataFrame:
    """A summary of LONG_METHODS x LONG_CONDITIONS with wide numbers: negative AHC bounds,
    four-digit times, rotation errors; visual-compass gives no home direction (NaN)."""
    rows = []
    for condition in LONG_CONDITIONS:
        for k, method in enumerate(LONG_METHODS):
            none = method == "visual-compass"
            metrics = {"ahc": -0.123, "ahc_lo": -0.456, "ahc_hi": 0.789, "rr": 0.812,
                       "rr_lo": 0.611, "rr_hi": 1.0, "mean_ae_deg": 123.456,
                       "mean_ae_deg_lo": 100.5, "mean_ae_deg_hi": 140.25, "ahc_missing90": -0.25,
                       "no_estimate_share": 0.125 * (k % 3)}  # fmt: skip
            rows.append({
                "condition": condition, "method": method, "n_goals": 5, "pairs": 845,
                **{c: math.nan if none else v for c, v in metrics.items()},
                "median_ae_deg": 99.5, "rotation_error_deg": 123.456,
                "rotation_error_deg_lo": 100.5, "rotation_error_deg_hi": 140.25,
                "rotation_flip_share": 0.125, "catchment": 0.25, "describe_ms": 1234.5,
                "home_ms": 9876.5 if k % 2 else 0.0123,
            })  # fmt: skip
    return pd.DataFrame(rows)


def test_the_headline_table_fits_the_pdf_page_without_shrinking() -> None:
    summary = _long_summary()
    order = RowOrder(tuple(LONG_CONDITIONS), tuple(LONG_METHODS))
    view = headline_view(summary, order, pd.DataFrame(columns=COLUMNS))
    assert view.shown_columns() == [
        "condition", "method", "AHC", "AHC (no est. = 90 deg)", "no est. [%]", "RR",
        "mean AE [deg]", "rotation error [deg]", "rotation flips [%]", "home [ms]",
    ]  # fmt: skip
    shown = view.text_frame()
    assert shown.loc[0, "AHC"] == "-0.123 [-0.456, 0.789]"
    assert shown.loc[1, ["AHC (no est. = 90 deg)", "no est. [%]"]].tolist() == ["-0.250", "12.5"]
    assert shown.loc[0, "RR"] == "0.812 [0.611, 1.000]"
    assert shown.loc[0, "rotation flips [%]"] == "12.5"
    compass = shown[shown["method"] == "visual-compass"]
    directions = ["AHC", "AHC (no est. = 90 deg)", "no est. [%]", "RR", "mean AE [deg]"]
    assert (compass[directions] == MISSING_TEXT).all().all()
    pages = table_pages(view)
    assert len(pages) == math.ceil(len(summary) / TABLE_ROWS)
    for page in pages:
        renderer = FigureCanvasAgg(page).get_renderer()
        page.draw(renderer)
        (table,) = page.axes[0].tables
        sizes = {cell.get_text().get_fontsize() for cell in table.get_celld().values()}
        assert sizes == {TABLE_FONT_SIZE}  # not shrunk to fit the width
        box = table.get_window_extent(renderer)
        assert box.x0 >= 0 and box.x1 <= page.bbox.width
        notes = page.texts[-1].get_window_extent(renderer)
        assert notes.y0 >= 0 and notes.y1 <= box.y0  # the notes below the table, on the page
    # LaTeX: the condition heads its methods' rows, one column narrower
    latex = to_latex(view)
    _check_latex(latex)
    assert "\\begin{longtable}{lrSSrSSSS}" in latex and "original-day &" not in latex
    heading = "\\multicolumn{9}{l}{\\itshape condition original-day} \\\\\nwarping & -0.123"
    assert latex.count("\\multicolumn{9}{l}{\\itshape condition") == 5 and heading in latex
    # the full summary is still written, every column with its interval
    full = summary_view(summary, order, pd.DataFrame(columns=COLUMNS))
    assert {"median AE [deg]", "catchment", "describe [ms/image]"} <= set(full.shown_columns())


def test_the_console_summary_fits_100_columns() -> None:
    summary = _long_summary()
    order = RowOrder(tuple(LONG_CONDITIONS), tuple(LONG_METHODS))
    text = console_summary(summary, order, pd.DataFrame(columns=COLUMNS))
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= CONSOLE_WIDTH
    # a condition heads its methods' rows; AHC with its interval, then the AHC with a missing
    # estimate as 90 deg and the share without an estimate; RR without its interval; no
    # rotation columns
    assert lines[1].split() == ["method", "AHC", "AHC90", "no", "est.", "[%]", "RR", "mean",
                                "AE", "[deg]", "home", "[ms]"]  # fmt: skip
    assert lines[lines.index("condition original-day") + 2].split()[:7] == [
        "min-warping", "-0.123", "[-0.456,", "0.789]", "-0.250", "12.5", "0.812"
    ]  # fmt: skip
    compass = [line for line in lines if line.strip().startswith("visual-compass")]
    assert len(compass) == 5 and all(line.split()[1:6] == ["--"] * 5 for line in compass)
    assert "AHC90: the same with a missing estimate counted as 90 deg" in " ".join(text.split())


def test_an_abstaining_method_shows_its_ahc90_and_share_in_the_headline_and_console(
    views: dict, tmp_path: Path
) -> None:
    """holes_10 abstains on 3 of 19 pairs a goal: its AHC over the rest is cos 10 deg, with the
    3 as 90 deg the cosine of a mean AE of (16 * 10 + 3 * 90) / 19 deg, and 15.8 % of its pairs
    have no estimate."""
    ahc90 = f"{math.cos(math.radians((16 * 10 + 3 * 90) / 19)):.3f}"
    headline = views["headline"].text_frame().set_index(["condition", "method"])
    holes = headline.loc[("a-a", "holes_10")]
    assert holes["AHC"] == "0.985 [0.985, 0.985]"
    assert (holes["AHC (no est. = 90 deg)"], holes["no est. [%]"]) == (ahc90, "15.8")
    assert headline.loc[("a-a", "perfect"), "no est. [%]"] == "0.0"
    run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS)
    tables = build_tables(run, MetricsConfig())
    lines = console_summary(tables.summary, ORDER, tables.comparisons).splitlines()
    assert lines[1].split()[:5] == ["method", "AHC", "AHC90", "no", "est."]
    row = next(line for line in lines if line.strip().startswith("holes_10"))
    assert row.split()[1:6] == ["0.985", "[0.985,", "0.985]", ahc90, "15.8"]


def test_headers_name_the_ahc_definition_the_run_chose(views: dict, tmp_path: Path) -> None:
    """A run whose AHC is the mean of cos(AE) (metrics.ahc.definition: mean_cos): every AHC
    header and title says so, and the notes say what it is; the default's read "AHC"."""
    assert views["headline"].shown_columns()[2:4] == ["AHC", "AHC (no est. = 90 deg)"]
    run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS)
    metrics = MetricsConfig.model_validate({"ahc": {"definition": "mean_cos"}})
    tables = build_tables(run, metrics)
    chosen = {v.name: v for v in report_views(tables, ORDER)}
    mean_cos = ["AHC (mean cos)", "AHC (mean cos; no est. = 90 deg)"]
    assert chosen["headline"].shown_columns()[2:4] == mean_cos
    assert set(mean_cos) <= set(chosen["bands"].shown_columns())
    summary = chosen["summary"].shown_columns()
    assert {"AHC (mean cos)", "AHC (mean cos; no estimate = 90 deg)"} <= set(summary)
    assert "AHC" not in summary and "AHC" not in chosen["headline"].shown_columns()
    assert chosen["ahc_by_distance"].title.startswith("AHC (mean cos) by distance")
    assert "AHC (mean cos)" in set(chosen["comparisons"].frame["metric"])
    assert "AHC (mean cos): the mean of cos(AE)" in " ".join(chosen["headline"].notes)
    console = console_summary(tables.summary, ORDER, tables.comparisons, metrics.ahc)
    assert console.splitlines()[1].split()[1:4] == ["AHC", "(mean", "cos)"]
    assert "AHC (mean cos): the mean of cos(AE)" in " ".join(console.split())
    assert max(len(line) for line in console.splitlines()) <= CONSOLE_WIDTH


def test_the_band_view_shows_each_methods_bands_nearest_first(tmp_path: Path) -> None:
    run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS)
    metrics = MetricsConfig.model_validate({"band_edges_m": [0.5, 1.0]})
    view = band_view(build_tables(run, metrics).bands, ORDER, metrics.ahc)
    assert view.shown_columns() == [
        "condition", "method", "distance", "pairs", "AHC", "AHC (no est. = 90 deg)",
        "no est. [%]", "mean AE [deg]", "rotation error [deg]", "rotation flips [%]",
    ]  # fmt: skip
    shown = view.text_frame()
    assert list(shown["condition"].unique()) == list(CONDITIONS)
    first = shown[shown["condition"] == CONDITIONS[0]]
    assert list(first["method"]) == [m.label for m in METHODS for _ in range(3)]
    assert list(first["distance"][:3]) == ["0-0.5 m", "0.5-1 m", "from 1 m"]
    # holes_10 lacks the estimate of the one pair beyond 1 m: no AHC there, AHC90 of 0
    far = first[(first["method"] == "holes_10") & (first["distance"] == "from 1 m")].iloc[0]
    assert (far["AHC"], far["AHC (no est. = 90 deg)"], far["no est. [%]"]) == ("--", "0.000",
                                                                               "100.0")  # fmt: skip
    (page, *_) = table_pages(view)
    renderer = FigureCanvasAgg(page).get_renderer()
    page.draw(renderer)
    box = page.axes[0].tables[0].get_window_extent(renderer)
    assert box.x0 >= 0 and box.x1 <= page.bbox.width


def test_a_method_without_home_directions_is_never_ranked() -> None:
    """visual-compass (NaN: no AE, AHC or RR) has no comparison rows: the best of the others
    is still marked when it beats them all, and the compass never is."""
    pairs = synthetic_pairs({"good": (0.0, 3.0), "bad": (15.0, 3.0)})
    tables = _run_tables(pairs)
    comparisons = method_comparisons(tables)
    compass = tables.summary.iloc[[0]].assign(method="visual-compass")
    metrics = [c for c in compass.columns if c.startswith(("ahc", "rr", "mean_ae", "median_ae"))]
    compass[metrics] = math.nan
    summary = pd.concat([tables.summary, compass], ignore_index=True)
    view = summary_view(summary, RowOrder(), comparisons)
    marked = {(view.frame.loc[row, "method"], column) for row, column in view.marked}
    assert marked == {("good", "mean AE [deg]"), ("good", "AHC"),
                      ("good", "AHC (no estimate = 90 deg)")}  # fmt: skip


def test_every_line_homebench_run_prints_fits_100_columns(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A quick-start-sized run with long condition and method names, one of which gives no
    home direction."""
    monkeypatch.chdir(tmp_path)  # the run's folder as a user names it: a short path
    methods = ["warping", "fourier-warping", "min-warping", "visual-compass"]
    config = arena_config(
        tmp_path, arena_manifest, output="run",
        databases={"original": str(arena_manifest), "twilight": str(arena_manifest)},
        conditions=["original-original", "original-twilight"], goals=[[1, 2], [2, 3], [3, 1]],
        methods=[{"method": m} for m in methods],
    )  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert "condition original-twilight" in lines
    assert [line for line in lines if len(line) > CONSOLE_WIDTH] == []


# --------------------------------------------------------------------------- run folder


def test_pairs_table_has_every_angle_in_radians_and_degrees(tmp_path: Path) -> None:
    run = write_fake_run(tmp_path / "run", METHODS)
    tables = build_tables(run, MetricsConfig())
    written = write_tables(tables, run, "csv")
    pairs = pd.read_csv(run / "tables" / "pairs.csv")
    for name in ANGLE_COLUMNS:
        assert name not in pairs.columns
        radians, degrees = pairs[f"{name}_rad"], pairs[f"{name}_deg"]
        np.testing.assert_allclose(degrees, radians * 180 / np.pi, rtol=1e-5)
        np.testing.assert_allclose(radians, tables.pairs[name].astype(float), rtol=1e-5)
    place = list(pairs.columns).index("estimate_rad")
    assert pairs.columns[place + 1] == "estimate_deg"
    assert (pairs.loc[pairs["method"] == "holes_10", "ae_deg"].dropna().round(6) == 10).all()
    assert "ae" in tables.pairs.columns and "estimate" in tables.pairs.columns  # in memory
    comparisons = pd.read_csv(run / "tables" / "comparisons.csv")
    assert list(comparisons.columns) == COLUMNS and len(comparisons) == 3 * 3
    assert run / "tables" / "comparisons.csv" in written


def test_comparisons_are_per_style_when_styles_are_swept() -> None:
    pairs = synthetic_pairs({"a": (0.0, 3.0), "b": (5.0, 3.0)})
    swept = pd.concat([pairs.assign(style=style) for style in ("lab", "corridor")])
    swept["style"] = swept["style"].astype("string")
    made = synthetic_tables(swept)
    found = method_comparisons(
        RunTables(
            swept, made["summary"], made["goals"], made["ahc"], (), rr_starts=made["rr_starts"]
        )  # fmt: skip
    )
    assert list(found.columns) == ["style", *COLUMNS]
    assert found["style"].tolist() == ["corridor"] * 3 + ["lab"] * 3
    # the same pairs in each style: the same comparisons, Holm within each style
    numbers = ["difference", "p_goal_holm"]
    np.testing.assert_array_equal(found[numbers][:3].to_numpy(), found[numbers][3:].to_numpy())
