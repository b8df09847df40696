"""``homebench report``: tables, figures and the PDF (plus HTML / Markdown) of a run folder.

Everything comes from the run folder alone, and the output is reproducible: the PDF's dates
are the run's start (environment.json), PNGs carry no date, so two reports of the same run are
byte-identical.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from homebench import __version__
from homebench.errors import DataError
from homebench.fileio import atomic_write, write_text_atomic
from homebench.report.figure_data import (
    condition_goals,
    goal_panels,
    image_describe_times,
    pick_goals,
)
from homebench.report.grid_figures import ae_figure, field_figure, goal_subtitle
from homebench.report.markup import FigureEntry, html_report, markdown_report
from homebench.report.metric_figures import ahc_figure, rr_figure, timing_figure
from homebench.report.pages import run_summary, table_pages, title_pages, warning_pages
from homebench.report.route_report import (
    load_route_run,
    route_run_figures,
    route_summary,
    route_views,
)
from homebench.report.run_data import RunData, RunInfo, grid_run, read_run_info
from homebench.report.style import method_styles, report_style, save_png
from homebench.report.tables import TableView, report_views, write_views

FORMATS = ("pdf", "html", "md")
#: Goals per condition drawn as vector fields and AE maps unless told otherwise.
DEFAULT_MAX_GOALS = 4
REPORT_FOLDER = "report"


#: (file stem, section heading, caption, figure) of each figure of a report, in order.
FigureSource = Callable[[], Iterator[tuple[str, str, str, Figure]]]


@dataclass(frozen=True)
class ReportOutcome:
    files: list[Path]  # everything written: tables, PNGs, report documents
    warnings: list[str]  # missing job (or trial) results, one line each


@dataclass(frozen=True)
class ReportContent:
    """What a report shows, whatever the kind of run: the title page's ``summary``, the
    tables (the first ``pdf_tables`` of them also in the PDF), warnings and the figures."""

    run: RunInfo
    summary: dict[str, list[str]]
    views: list[TableView]
    pdf_tables: int
    warnings: list[str]
    figures: FigureSource


def _condition_figures(
    run: RunData, condition: str, max_goals: int
) -> Iterator[tuple[str, str, Figure]]:
    """(file stem, caption, figure) of one condition, in the paper's order (Figures 7-10)."""
    tables = run.tables
    styles = method_styles(tables.pairs["method"].unique())
    where = run.condition_title(condition)
    pairs = tables.pairs[tables.pairs["condition"] == condition]
    goals = condition_goals(tables.pairs, condition)
    shown = pick_goals(goals, max_goals)
    note = "" if len(shown) == len(goals) else f" ({len(shown)} of {len(goals)} goals shown)"
    for goal in shown:
        panels = goal_panels(pairs, run.metrics, condition, goal)
        subtitle = goal_subtitle(goal, panels[0].field.grid)
        stem = f"{condition}_goal_{goal[0]}_{goal[1]}"
        caption = f"Home-vector fields, {where}, {subtitle}{note}"
        yield f"{stem}_field", caption, field_figure(panels, styles, caption)
        caption = f"Angular error, {where}, {subtitle}"
        yield f"{stem}_ae", caption, ae_figure(panels, caption)
    caption = f"AHC against distance, {where}"
    ahc = tables.ahc[tables.ahc["condition"] == condition]
    yield f"{condition}_ahc", caption, ahc_figure(ahc, styles, caption)
    caption = f"Return ratio per goal, {where}"
    per_goal = tables.goals[tables.goals["condition"] == condition]
    yield f"{condition}_rr", caption, rr_figure(per_goal, styles, caption)
    caption = f"Time per call, {where}"
    describe = image_describe_times(pairs)
    yield f"{condition}_timing", caption, timing_figure(describe, pairs, styles, caption)


def _grid_figures(run: RunData, max_goals: int) -> Iterator[tuple[str, str, str, Figure]]:
    """Every condition's figures, grouped by condition in the config's order."""
    for condition in run.conditions:
        section = run.condition_title(condition)
        for stem, caption, fig in _condition_figures(run, condition, max_goals):
            yield stem, section, caption, fig


def _grid_content(info: RunInfo, max_goals: int) -> ReportContent:
    run = grid_run(info)
    warnings = list(run.tables.missing_jobs)
    if run.tables.pairs.empty:
        shown = "; ".join(warnings[:3]) + (" ..." if len(warnings) > 3 else "")
        raise DataError(f"{run.run_dir}: no job results to report on (missing: {shown})")
    views = report_views(run.tables)
    figures = partial(_grid_figures, run, max_goals)
    return ReportContent(run, run_summary(run), views, 1, warnings, figures)


def _route_content(info: RunInfo) -> ReportContent:
    run = load_route_run(info)
    views = route_views(run)
    figures = partial(route_run_figures, run)
    return ReportContent(info, route_summary(run), views, len(views), run.warnings, figures)


def load_content(run_dir: Path, max_goals: int = DEFAULT_MAX_GOALS) -> ReportContent:
    """What the report of ``run_dir`` shows, by the run's kind (grid or route)."""
    info = read_run_info(run_dir)
    if info.kind == "route":
        return _route_content(info)
    return _grid_content(info, max_goals)


def _pdf_metadata(run: RunInfo) -> dict[str, object]:
    return {
        "Title": f"homebench report: {run.name}",
        "Creator": f"homebench {__version__}",
        "CreationDate": run.started,
        "ModDate": run.started,
    }


def _write_figures(content: ReportContent, folder: Path, pdf: PdfPages | None) -> list[FigureEntry]:
    """Write every figure as PNG under ``folder`` (and as a page of ``pdf``)."""
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for stem, section, caption, fig in content.figures():
        path = save_png(fig, folder / f"{stem}.png")
        if pdf is not None:
            pdf.savefig(fig)
        plt.close(fig)
        entries.append(FigureEntry(path, section, caption))
    return entries


def _pdf_pages(pdf: PdfPages, pages: Sequence[Figure]) -> None:
    for fig in pages:
        pdf.savefig(fig)
        plt.close(fig)


def write_report(
    run_dir: Path,
    formats: Sequence[str] = ("pdf",),
    out_dir: Path | None = None,
    max_goals: int = DEFAULT_MAX_GOALS,
) -> ReportOutcome:
    """Write the report of ``run_dir`` (a grid or a route run) under ``out_dir`` (default
    ``run_dir/report``).

    Always: ``tables/`` (grid: summary, RR per goal, AHC per distance; route: per route length
    and per trial; as CSV, MD and TeX) and ``figures/*.png``; then ``report.pdf``,
    ``report.html`` and / or ``report.md`` as ``formats`` asks. Grid fields and AE maps are
    drawn for at most ``max_goals`` goals per condition. Raises DataError when the folder is
    not a run or has no result at all; missing job or trial results otherwise become a warning
    page (and ``warnings``).
    """
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown:
        raise ValueError(f"unknown report format(s) {unknown}; choose from {FORMATS}")
    if max_goals < 1:
        raise ValueError(f"max_goals must be at least 1, got {max_goals}")
    content = load_content(run_dir, max_goals)
    run = content.run
    folder = Path(out_dir) if out_dir is not None else run.run_dir / REPORT_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    tables = write_views(content.views, folder / "tables")
    documents = []
    with report_style():
        if "pdf" in formats:
            path = folder / "report.pdf"
            with atomic_write(path) as f, PdfPages(f, metadata=_pdf_metadata(run)) as pdf:
                figures = _write_run_pdf(content, folder, pdf)
            documents.append(path)
        else:
            figures = _write_figures(content, folder / "figures", None)
    for suffix, render in (("md", markdown_report), ("html", html_report)):
        if suffix in formats:
            path = folder / f"report.{suffix}"
            text = render(run, content.summary, content.views, figures, content.warnings, folder)
            write_text_atomic(path, text)
            documents.append(path)
    files = [*tables, *(entry.path for entry in figures), *documents]
    return ReportOutcome(files, content.warnings)


def _write_run_pdf(content: ReportContent, folder: Path, pdf: PdfPages) -> list[FigureEntry]:
    """Title page, warnings, the tables, then the figures in their sections' order."""
    _pdf_pages(pdf, title_pages(content.run, content.summary))
    _pdf_pages(pdf, warning_pages(content.warnings) if content.warnings else [])
    for view in content.views[: content.pdf_tables]:
        _pdf_pages(pdf, table_pages(view))
    return _write_figures(content, folder / "figures", pdf)
