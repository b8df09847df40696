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
from matplotlib.lines import Line2D
from matplotlib.transforms import Bbox
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main
from homebench.report import document
from homebench.report.appendix import (
    CONFIG_TITLE,
    DEFINITIONS_TITLE,
    ENVIRONMENT_TITLE,
    environment_sections,
    json_lines,
)
from homebench.report.captions import add_caption, numbered
from homebench.report.definitions import definitions
from homebench.report.document import load_content, write_report
from homebench.report.heatmaps import HEAT_METRICS, _grid, heatmap_columns, heatmap_figure
from homebench.report.pages import appendix_pages
from homebench.report.style import report_style, save_figure

METHODS = [FakeMethod("warping", 20.0), FakeMethod("mine", 90.0, frozenset({(0, 0)}))]
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


def _boxes(fig: plt.Figure) -> list:
    """The display boxes of the axes (frame, ticks, labels, title), legends and texts of a
    figure but its last text (the caption)."""
    renderer = fig.canvas.get_renderer()
    axes = [ax.get_tightbbox(renderer, bbox_extra_artists=[]) for ax in fig.axes]
    others = [a.get_tightbbox(renderer) for a in [*fig.legends, *fig.texts[:-1]]]
    return [box for box in [*axes, *others] if box is not None]


def test_captions_sit_below_every_figure_of_a_report(tmp_path: Path) -> None:
    content = load_content(_fake_run(tmp_path / "run"), max_goals=1)
    with report_style():
        for _, _, caption, fig in content.figures():
            text = add_caption(fig, numbered(7, caption))
            fig.canvas.draw()
            box = text.get_window_extent(fig.canvas.get_renderer())
            assert text.get_text().replace("\n", " ") == f"Figure 7. {caption}"
            assert box.x0 >= 0 and box.x1 <= fig.bbox.x1 and box.y0 >= 0, caption
            assert not any(box.overlaps(other) for other in _boxes(fig)), caption
            plt.close(fig)


def _inches(fig: plt.Figure, box: Bbox) -> tuple[float, float, float, float]:
    """``box`` (figure fractions) as inches: from the left, from the top, width, height."""
    width, height = fig.get_size_inches()
    return box.x0 * width, (1 - box.y1) * height, box.width * width, box.height * height


def test_a_caption_clears_a_legend_below_and_a_colour_bar() -> None:
    with report_style():
        fig = plt.figure(figsize=(7.2, 4.0), layout="constrained")
        axes = fig.subplots(1, 2)
        mesh = axes[0].pcolormesh(np.arange(20.0).reshape(4, 5))
        fig.colorbar(mesh, ax=axes)
        fig.legend(handles=[Line2D([], [], label="a")], loc="outside lower center")
        fig.suptitle("title")
        fig.draw_without_rendering()
        before = [_inches(fig, ax.get_position()) for ax in fig.axes]
        text = add_caption(fig, "word " * 120)
        fig.canvas.draw()
        # axes keep their size and their distances from the top
        after = [_inches(fig, ax.get_position()) for ax in fig.axes]
        np.testing.assert_allclose(after, before, atol=1e-3)  # a new layout run: 1e-4 in off
        box = text.get_window_extent(fig.canvas.get_renderer())
        assert text.get_text().count("\n") >= 3
        assert box.x1 <= fig.bbox.x1
        assert not any(box.overlaps(other) for other in _boxes(fig))
        plt.close(fig)


def test_a_figure_laid_out_by_its_files_is_not_drawn_again_for_its_caption(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """save_figure lays the figure out and stops its engine (a placeholder engine remains):
    the caption reuses that layout instead of drawing the figure once more."""
    with report_style():
        fig = plt.figure(figsize=(4.0, 3.0), layout="constrained")
        fig.subplots().plot([0, 1], [1, 0])
        save_figure(fig, tmp_path / "figure")
        draws = []
        monkeypatch.setattr(fig, "draw_without_rendering", lambda: draws.append(1))
        add_caption(fig, "a caption")
        assert draws == []
        plt.close(fig)


def test_a_sweep_gets_heat_maps_instead_of_condition_pages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(document, "MAX_DETAILED_CONDITIONS", 1)
    run = _fake_run(tmp_path / "run", ("orig-orig", "orig-day"))
    outcome = write_report(run, ["pdf", "md"], max_goals=1)
    texts = _texts(run / "report" / "report.pdf")
    assert "2 conditions (more than 1): this report shows overview heat maps" in texts[0]
    captioned = [text for text in texts if "Figure " in text]
    for text, label in zip(captioned, ("AHC", "RR", "mean AE [deg]"), strict=False):
        assert f"{label} of each method (rows) under each condition (columns)" in text
    # the documents show the heat maps and the all-conditions figures, and nothing else
    markdown = (run / "report" / "report.md").read_text()
    sections = markdown.split("\n## ")
    shown = {s.split("\n")[0]: s.count("](figures/") for s in sections if "](figures/" in s}
    assert shown == {"Overview": 3, document.METRICS_SECTION: len(captioned) - 3}
    assert all(f"Figure {k}." in text for k, text in enumerate(captioned, start=1))
    # every condition's figures are still written, in three formats
    for condition in ("orig-orig", "orig-day"):
        written = [p for p in outcome.files if p.name.startswith(f"{condition}_")]
        assert {p.suffix for p in written} == {".png", ".pdf", ".svg"}
        assert f"figures/{condition}_" not in markdown
    names = {p.name for p in outcome.files}
    assert {"heatmap_ahc.png", "heatmap_ahc.pdf", "heatmap_ahc.svg"} <= names


def _summary() -> pd.DataFrame:
    """Method m ran in style b only, n in style a only."""
    rows = [("b", "y-y", "m", 0.5, 1.0, 60.0), ("b", "x-x", "m", -0.25, np.nan, 104.0),
            ("a", "y-y", "n", 1.0, 0.0, 0.0), ("a", "x-x", "n", 0.123, 0.5, 50.05)]  # fmt: skip
    return pd.DataFrame(rows, columns=["style", "condition", "method", "ahc", "rr",
                                       "mean_ae_deg"])  # fmt: skip


def test_heat_map_columns_follow_the_config_and_cells_show_their_values() -> None:
    summary = _summary()
    columns = heatmap_columns(summary, ["y-y", "x-x"])
    assert columns == [("a", "y-y"), ("a", "x-x"), ("b", "y-y"), ("b", "x-x")]
    with report_style():
        expected = {
            "ahc": ["1.00", "0.12", "0.50", "-0.25"],
            "rr": ["0.00", "0.50", "1.00", "n/a"],
            "mean_ae_deg": ["0.0", "50.0", "60.0", "104.0"],
        }
        for metric in HEAT_METRICS:
            grid = _grid(summary, columns, metric.column)
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
    assert any(h.startswith("Catchment") for h in definitions(True))
    assert not any(h.startswith("Catchment") for h in definitions(False))


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
