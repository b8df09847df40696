"""The report document: captions, the definitions / config / environment appendix, heat maps of
sweeps, the progress bar."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pypdf
import pytest
from click.testing import CliRunner
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main
from homebench.config import AhcConfig, MetricsConfig
from homebench.report import document
from homebench.report.appendix import (
    CONFIG_TITLE,
    DEFINITIONS_TITLE,
    ENVIRONMENT_TITLE,
    environment_sections,
    json_lines,
)
from homebench.report.captions import (
    CAPTION_LINE_HEIGHT,
    MAX_SCALE,
    ORIENTATIONS,
    PAGE_MARGIN,
    numbered,
    place_figure,
)
from homebench.report.definitions import definitions
from homebench.report.document import load_content, write_report
from homebench.report.figure_files import draw_figure
from homebench.report.grid import report as grid_report
from homebench.report.grid.heatmaps import (
    HEAT_METRICS,
    _grid,
    heat_metrics,
    heatmap_columns,
    heatmap_figure,
)
from homebench.report.pages import appendix_pages, run_summary
from homebench.report.run_data import load_run
from homebench.report.style import report_style

METHODS = [FakeMethod("warping", 20.0), FakeMethod("mine", 90.0, frozenset({(0, 0)}))]
#: The heat maps of a run in which a method ("mine") abstains, in order.
HEAT_LABELS = ("AHC", "AHC (no est. = 90 deg)", "no estimate [%]", "RR", "mean AE [deg]")
#: What a real run records beyond the fake run's environment.
RECORDED = {
    "homebench": "0.1.0",
    "git": {"commit": "0123abcd" * 5, "dirty": True},
    "cpu": {"model": "Test CPU 3000", "count": 2},
    "command": ["homebench", "run", "my config.yaml", "goals=all"],
    "config_hash": "c0ffee" * 10,
    "overrides": {"config": ["goals=all"]},
    "methods": {"warping": {"distribution": "homebench", "version": "0.1.0",
                            "code_version": "homebench 0.1.0 4bd4a8d3"}},  # fmt: skip
    "databases": {"orig": {"identity": "orig-1234", "locator": "/data/orig",
                           "manifest_sha256": "ab" * 32}},  # fmt: skip
    "data_checks": {"orig-1234": {"reference": "synth-original", "checked": 20,
                                  "identical": 18, "tolerated": 1, "differing": ["p_0_0.png"]}},
}  # fmt: skip


def _fake_run(folder: Path, conditions: tuple[str, ...] = ("orig-orig",)) -> Path:
    run = write_fake_run(folder, METHODS, conditions=conditions, name="fake-run")
    environment = json.loads((run / "environment.json").read_text())
    (run / "environment.json").write_text(json.dumps({**environment, **RECORDED}))
    return run


def _texts(pdf: Path) -> list[str]:
    """Each page's text, runs of white space (wrapped lines) as one space."""
    return [" ".join(page.extract_text().split()) for page in pypdf.PdfReader(pdf).pages]


def test_the_pdf_has_numbered_captions_and_the_appendix(tmp_path: Path) -> None:
    run = _fake_run(tmp_path / "run")
    write_report(run, ["pdf", "html", "md"], max_goals=1)
    folder = run / "report"
    texts = _texts(folder / "report.pdf")
    figure_pages = [k for k, text in enumerate(texts) if "Figure " in text]
    # one condition, one goal drawn: field, AE, AHC, RR and timing figures, numbered in order
    assert len(figure_pages) == 5
    for number, page in enumerate(figure_pages, start=1):
        assert f"Figure {number}." in texts[page]
    appendix = "\n".join(texts[figure_pages[-1] + 1 :]).lower()  # headings are in capitals
    for expected in (
        DEFINITIONS_TITLE, "AHC = cos(mean AE)", "no est. = 90 deg", "Moeller", "Catchment",
        "expanded percentile", "sign-flip", "Wilcoxon", "McNemar", "Holm",
        CONFIG_TITLE, '"name": "fake-run"', '"conditions": ["orig-orig"]',
        "ENVIRONMENT", "git commit: " + "0123abcd" * 5 + " (dirty", "Test CPU 3000",
        "homebench run 'my config.yaml' goals=all", "testhost", "c0ffee" * 10,
        "manifest sha256 " + "ab" * 32, "18 of 20 files byte-identical", "p_0_0.png",
    ):  # fmt: skip
        assert expected.lower() in appendix, expected
    html = (folder / "report.html").read_text()
    markdown = (folder / "report.md").read_text()
    assert "<figcaption>Figure 1. " in html and "<figcaption>Figure 5. " in html
    assert "\n*Figure 1. " in markdown and "\n*Figure 5. " in markdown
    for text in (html, markdown):
        assert DEFINITIONS_TITLE in text and CONFIG_TITLE in text and "Test CPU 3000" in text
    # beside the timing columns and in the timing figure's caption: the host's load
    timing = next(texts[k] for k in figure_pages if "Time per call" in texts[k])
    assert "load while this run timed its jobs was not recorded" in timing
    assert markdown.count("The host's load while this run timed its jobs was not recorded") >= 2


def _check_placement(figure: tuple[float, float], caption: str) -> None:
    """``figure`` sits on an A4 page inside its margins, as large as the page allows (up to
    MAX_SCALE), with ``caption`` below it and above the bottom margin."""
    placement = place_figure(figure, caption)
    width, height = placement.size
    assert placement.size in ORIENTATIONS
    left, bottom, right, top = placement.figure_box(figure)
    tolerance = 1e-9
    assert left >= PAGE_MARGIN - tolerance and right <= width - PAGE_MARGIN + tolerance
    assert top <= height - PAGE_MARGIN + tolerance
    assert placement.caption_top < bottom
    assert placement.caption_bottom >= PAGE_MARGIN - CAPTION_LINE_HEIGHT  # a line's leading
    fills_width = right - left >= width - 2 * PAGE_MARGIN - 1e-6
    fills_height = placement.caption_bottom <= PAGE_MARGIN + 1e-6
    assert fills_width or fills_height or placement.scale == MAX_SCALE, (figure, placement)


def test_every_figure_of_a_report_fills_an_a4_page_above_its_caption(tmp_path: Path) -> None:
    content = load_content(_fake_run(tmp_path / "run", ("orig-orig", "orig-day")), max_goals=1)
    with report_style():
        for _, _, caption, fig in content.figures():
            width, height = fig.get_size_inches()
            _check_placement((float(width), float(height)), numbered(7, caption))
            plt.close(fig)


@pytest.mark.parametrize(
    ("figure", "orientation", "scale"),
    [
        ((7.2, 3.0), ORIENTATIONS[0], (ORIENTATIONS[0][0] - 2 * PAGE_MARGIN) / 7.2),
        ((7.2, 9.5), ORIENTATIONS[1], None),  # a tall figure: portrait
        ((3.5, 2.5), ORIENTATIONS[0], MAX_SCALE),  # a small one is not blown up
    ],
)
def test_a_figure_page_takes_the_orientation_that_shows_it_larger(
    figure: tuple[float, float], orientation: tuple[float, float], scale: float | None
) -> None:
    caption = "Figure 1. " + "word " * 60
    _check_placement(figure, caption)
    placement = place_figure(figure, caption)
    assert placement.size == orientation
    if scale is not None:
        assert placement.scale == pytest.approx(scale)


def test_a_figure_page_takes_the_figure_file_as_drawn(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The page is the figure's PDF file placed on the page: the figure is drawn once per file
    (PNG, PDF, SVG) and once to lay it out, not once more for its page."""
    with report_style():
        fig = plt.figure(figsize=(7.2, 3.0), layout="constrained")
        fig.subplots().plot([0, 1], [1, 0])
        draws = []
        original = fig.draw
        monkeypatch.setattr(fig, "draw", lambda *a, **k: draws.append(1) or original(*a, **k))
        page = tmp_path / "page.pdf"
        draw_figure(fig, tmp_path / "figure", (page, "Figure 1. A line."))
        plt.close(fig)
    assert len(draws) == 4
    (only,) = pypdf.PdfReader(page).pages
    assert (float(only.mediabox.width) / 72, float(only.mediabox.height) / 72) == pytest.approx(
        ORIENTATIONS[0]
    )
    assert "Figure 1. A line." in only.extract_text()


@pytest.mark.slow  # CI time: one run's per-goal figures are tested below
def test_a_sweep_writes_its_per_goal_figures_as_files_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(grid_report, "MAX_DETAILED_CONDITIONS", 1)
    run = _fake_run(tmp_path / "run", ("orig-orig", "orig-day"))
    outcome = write_report(run, ["pdf", "md"], max_goals=1)
    texts = _texts(run / "report" / "report.pdf")
    assert "are in the figures folder only (2 conditions, more than 1)" in texts[0]
    captioned = [text for text in texts if "Figure " in text]
    for text, label in zip(captioned, HEAT_LABELS, strict=False):
        assert f"{label} of each method (rows) under each condition (columns)" in text
    # the documents show the heat maps, the all-conditions figures and the time per call
    markdown = (run / "report" / "report.md").read_text()
    sections = markdown.split("\n## ")
    shown = {s.split("\n")[0]: s.count("](figures/") for s in sections if "](figures/" in s}
    assert shown == {"Overview": 5, grid_report.METRICS_SECTION: 2, "Time per call": 1}
    assert len(captioned) == 8
    assert all(f"Figure {k}." in text for k, text in enumerate(captioned, start=1))
    # every condition's per-goal figures are still written, in three formats
    for condition in ("orig-orig", "orig-day"):
        written = [p for p in outcome.files if p.name.startswith(f"{condition}_")]
        assert {p.suffix for p in written} == {".png", ".pdf", ".svg"}
        assert f"figures/{condition}_" not in markdown
    names = {p.name for p in outcome.files}
    assert {"heatmap_ahc.png", "heatmap_ahc.pdf", "heatmap_ahc.svg"} <= names


def test_the_report_leads_with_the_headline_table_and_ends_with_per_goal_figures(
    tmp_path: Path,
) -> None:
    """Title, the headline and band tables, heat maps, AHC, RR, time per call, then the
    per-goal figures of each condition, then the definitions; every page A4."""
    run = _fake_run(tmp_path / "run", ("orig-orig", "orig-day"))
    write_report(run, ["pdf", "md"], max_goals=1)
    pdf = run / "report" / "report.pdf"
    texts = _texts(pdf)
    assert "Results per condition and method" in texts[1]
    assert ("condition method AHC AHC (no est. = 90 deg) no est. [%] RR mean AE [deg] rotation "
            "error [deg] rotation flips [%] home [ms]") in texts[1]  # fmt: skip
    assert "median AE [deg]" not in texts[1]  # the full summary is a file
    assert "Results per band of distance" in texts[2]
    starts = [
        *(f"{label} of each method" for label in HEAT_LABELS),
        "AHC against the distance", "Return ratio (RR) per goal", "Time per call, all conditions",
        "Home-vector fields, orig-orig", "Angular error (AE) per current position, orig-orig",
        "Home-vector fields, orig-day", "Angular error (AE) per current position, orig-day",
    ]  # fmt: skip
    figures = texts[3 : 3 + len(starts)]
    for number, (text, start) in enumerate(zip(figures, starts, strict=True), start=1):
        assert f"Figure {number}. {start}" in text
    assert texts[3 + len(starts)].startswith(DEFINITIONS_TITLE)
    sizes = {
        (round(float(page.mediabox.width) / 72, 2), round(float(page.mediabox.height) / 72, 2))
        for page in pypdf.PdfReader(pdf).pages
    }
    assert sizes <= {(11.69, 8.27), (8.27, 11.69)}
    markdown = (run / "report" / "report.md").read_text()
    headings = [line[3:] for line in markdown.splitlines() if line.startswith("## ")]
    assert headings.index("Overview") < headings.index(grid_report.METRICS_SECTION)
    per_goal = [h for h in headings if h.startswith(grid_report.PER_GOAL_SECTION)]
    assert [h.split(", ")[1].split(" ")[0] for h in per_goal] == ["orig-orig", "orig-day"]
    assert headings.index("Time per call") < headings.index(per_goal[0])
    bookmarks = [item.title for item in pypdf.PdfReader(pdf).outline]
    assert bookmarks == [document.FRONT_TITLE, "Overview", grid_report.METRICS_SECTION,
                         "Time per call", *per_goal, document.BACK_TITLE]  # fmt: skip


def _summary() -> pd.DataFrame:
    """Method m ran in style b only, n in style a only; m abstains on some pairs."""
    rows = [("b", "y-y", "m", 0.5, 0.25, 0.5, 1.0, 60.0),
            ("b", "x-x", "m", -0.25, -0.5, 0.25, np.nan, 104.0),
            ("a", "y-y", "n", 1.0, 1.0, 0.0, 0.0, 0.0),
            ("a", "x-x", "n", 0.123, 0.123, 0.0, 0.5, 50.05)]  # fmt: skip
    return pd.DataFrame(rows, columns=["style", "condition", "method", "ahc", "ahc_missing90",
                                       "no_estimate_share", "rr", "mean_ae_deg"])  # fmt: skip


def test_heat_map_columns_follow_the_config_and_cells_show_their_values() -> None:
    summary = _summary()
    columns = heatmap_columns(summary, ["y-y", "x-x"])
    assert columns == [("a", "y-y"), ("a", "x-x"), ("b", "y-y"), ("b", "x-x")]
    assert [metric.label for metric in heat_metrics(summary)] == list(HEAT_LABELS)
    with report_style():
        expected = {
            "ahc": ["1.00", "0.12", "0.50", "-0.25"],
            "ahc_missing90": ["1.00", "0.12", "0.25", "-0.50"],
            "no_estimate_share": ["0.0", "0.0", "50.0", "25.0"],
            "rr": ["0.00", "0.50", "1.00", "n/a"],
            "mean_ae_deg": ["0.0", "50.0", "60.0", "104.0"],
        }
        for metric in HEAT_METRICS:
            grid = _grid(summary, columns, metric)
            assert list(grid.index) == ["m", "n"]
            fig = heatmap_figure(grid, metric)
            ax = fig.axes[0]
            cells = [t.get_text() for t in ax.texts]
            values = expected[metric.column]
            # row m: no value in style a; row n: no value in style b
            assert cells == ["n/a", "n/a", *values[2:], *values[:2], "n/a", "n/a"]
            assert ax.collections[0].get_clim() == (metric.vmin, metric.vmax)
            labels = [t.get_text() for t in ax.get_xticklabels()]
            assert labels == ["a / y-y", "a / x-x", "b / y-y", "b / x-x"]
            plt.close(fig)


def test_abstention_maps_are_drawn_only_where_a_method_abstains_and_name_the_ahc() -> None:
    """Without a missing estimate the AHC with one as 90 deg is the AHC, and every share 0:
    those maps are left out; a run's AHC definition other than the default is named."""
    answered = _summary().assign(no_estimate_share=0.0)
    assert [metric.label for metric in heat_metrics(answered)] == ["AHC", "RR", "mean AE [deg]"]
    mean_cos = heat_metrics(_summary(), AhcConfig(definition="mean_cos"))
    assert [metric.label for metric in mean_cos][:3] == [
        "AHC (mean cos)", "AHC (mean cos; no est. = 90 deg)", "no estimate [%]"
    ]  # fmt: skip


def test_config_lines_are_json_with_short_containers_on_one_line() -> None:
    value = {"name": "x", "grid": {"shape": [10, 17], "spacing": 0.3},
             "long": ["a" * 40, "b" * 40], "empty": {}}  # fmt: skip
    lines = json_lines(value)
    assert lines == [
        "{",
        '  "name": "x",',
        '  "grid": {"shape": [10, 17], "spacing": 0.3},',
        '  "long": [',
        f'    "{"a" * 40}",',
        f'    "{"b" * 40}"',
        "  ],",
        '  "empty": {}',
        "}",
    ]
    assert json.loads("\n".join(lines)) == value


def test_a_sparse_environment_reads_not_recorded() -> None:
    sections = environment_sections({"git": None, "versions": {"python": "3.11.7"}})
    assert sections["Software"][:3] == [
        "homebench: not recorded",
        "git commit: not a git checkout",
        "python: 3.11.7",
    ]
    assert sections["Methods (code versions)"] == ["not recorded"]
    assert sections["Data sets (manifest checksums and reference checks)"] == [
        "databases: not recorded",
        "reference checks: not recorded",
    ]
    assert environment_sections({})["Software"][1] == "git commit: not recorded"


def test_definitions_name_the_catchment_only_when_computed() -> None:
    assert any(h.startswith("Catchment") for h in definitions(MetricsConfig(catchment=True)))
    assert not any(h.startswith("Catchment") for h in definitions(MetricsConfig(catchment=False)))


def test_definitions_and_title_page_say_the_rr_reading_and_its_units(tmp_path: Path) -> None:
    for reading in ("fail", "arrived"):
        said = definitions(MetricsConfig(return_ratio={"no_estimate": reading}))
        rr = " ".join(text for heading, texts in said.items() if "RR" in heading
                      for text in texts)  # fmt: skip
        assert "success radius (grid units" in rr
        assert f"no_estimate: {reading}" in rr
    metrics = run_summary(load_run(_fake_run(tmp_path / "run")))["Metrics"]
    rr_line = next(line for line in metrics if line.startswith("RR"))
    assert rr_line.startswith("RR (grid units): step 0.8, success radius 0.5")
    assert "no_estimate: fail" in rr_line


def test_a_long_config_continues_on_more_pages(tmp_path: Path) -> None:
    run = _fake_run(tmp_path / "run")
    content = load_content(run)
    long = content.appendix.__class__(
        {}, [f'"key_{k}": {k},' for k in range(250)], {"Software": ["homebench: 0.1.0"]}
    )
    pages = appendix_pages(long)
    texts = ["\n".join(t.get_text() for t in fig.texts) for fig in pages]
    for fig in pages:
        plt.close(fig)
    # 52 lines a column, two columns a page: 3 config pages, then the environment
    assert len(pages) == 4
    assert texts[1].startswith(f"{CONFIG_TITLE} (continued)") and '"key_249": 249,' in texts[2]
    assert texts[3].startswith(ENVIRONMENT_TITLE)


def test_cli_report_without_progress(tmp_path: Path) -> None:
    run = _fake_run(tmp_path / "run")
    result = CliRunner().invoke(
        main, ["report", str(run), "--format", "md", "--max-goals", "1", "--no-progress"]
    )
    assert result.exit_code == 0, result.output
    assert result.stderr == ""
    assert (run / "report" / "report.md").is_file()


def test_no_progress_bar_when_stderr_is_no_terminal(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write_report(_fake_run(tmp_path / "run"), ["md"], max_goals=1, progress=True)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("progress", [True, False])
def test_a_terminal_gets_a_progress_bar_over_the_figures_unless_told(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    progress: bool,
) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    write_report(_fake_run(tmp_path / "run"), ["md"], max_goals=1, progress=progress)
    err = capsys.readouterr().err
    assert ("report figures" in err and "figure/s" in err) == progress


def test_trailing_blank_lines_start_no_page_of_their_own() -> None:
    from homebench.report.pages import PROSE, _text_pages

    lines = [f"line {k}" for k in range(PROSE.lines * PROSE.columns)] + ["", ""]
    pages = _text_pages("Title", lines)
    assert len(pages) == 1
    for fig in pages:
        plt.close(fig)
