"""``homebench report``: tables, figures and the PDF (plus HTML / Markdown) of a run folder.

Everything comes from the run folder alone, and the output is reproducible: the PDF's dates
are the run's start (environment.json), figure files carry no date, so two reports of the same
run are byte-identical.

The PDF: the title page, warnings, the headline and band tables (the others are files), the
figures (each on an A4 page with its numbered caption below it; a grid run's in the order of
:mod:`~homebench.report.grid.report`, per-goal figures last) and an appendix: the definitions of
the metrics and statistics, the resolved config, the environment and the data sets' checksums.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from datetime import datetime
from functools import partial
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from tqdm import tqdm

from homebench import __version__
from homebench.analysis.tables import RunTables
from homebench.errors import DataError
from homebench.fileio import atomic_write, write_text_atomic
from homebench.report import DEFAULT_MAX_GOALS, reuse
from homebench.report.appendix import Appendix, run_appendix
from homebench.report.figure_files import FigureFiles, assemble_pdf
from homebench.report.grid.report import figures_note, grid_figures, shown_sections
from homebench.report.host_load import load_note
from homebench.report.markup import FigureEntry, html_report, markdown_report
from homebench.report.pages import (
    appendix_pages,
    run_summary,
    table_pages,
    title_pages,
    warning_pages,
)
from homebench.report.route.report import (
    load_route_run,
    route_run_figures,
    route_summary,
    route_views,
)
from homebench.report.run_data import RunInfo, grid_run, read_run_info
from homebench.report.style import figure_paths, report_style
from homebench.report.tables import TableView, report_views, run_order, write_views

FORMATS = ("pdf", "html", "md")
REPORT_FOLDER = "report"
#: The tables of a grid run's PDF (the others are files, and in the HTML and Markdown reports).
PDF_TABLES = ("headline", "bands")
#: Bookmarks of the PDF's text pages before and after the figures.
FRONT_TITLE = "Run and tables"
BACK_TITLE = "Definitions, configuration and environment"


#: (file stem, section heading, caption, figure) of each figure of a report, in order.
FigureSource = Callable[[], Iterator[tuple[str, str, str, Figure]]]


@dataclass(frozen=True)
class ReportOutcome:
    files: list[Path]  # everything written: tables, figure files, report documents
    warnings: list[str]  # missing job (or trial) results, one line each


@dataclass(frozen=True)
class ReportContent:
    """What a report shows, whatever the kind of run: the title page's ``summary``, the
    tables (the first ``pdf_tables`` of them also in the PDF), warnings, the figures and the
    appendix. ``sections``: the sections whose figures the documents show (None: all); the
    figures of the others are written as files only."""

    run: RunInfo
    summary: dict[str, list[str]]
    views: list[TableView]
    pdf_tables: int
    warnings: list[str]
    figures: FigureSource
    appendix: Appendix
    sections: frozenset[str] | None = None

    def in_documents(self, section: str) -> bool:
        """Whether the figures of ``section`` go into the PDF, HTML and Markdown reports."""
        return self.sections is None or section in self.sections


def _grid_content(
    info: RunInfo, max_goals: int | None, tables: RunTables | None = None
) -> ReportContent:
    run = grid_run(info, tables)
    warnings = list(run.tables.missing_jobs)
    if run.tables.pairs.empty:
        shown = "; ".join(warnings[:3]) + (" ..." if len(warnings) > 3 else "")
        raise DataError(f"{run.run_dir}: no job results to report on (missing: {shown})")
    views = report_views(run.tables, run_order(run), load_note(run.environment))
    summary = run_summary(run)
    summary["Figures"] = [figures_note(run, max_goals)]
    appendix = run_appendix(run, run.metrics)
    figures = partial(grid_figures, run, max_goals)
    pdf_tables = sum(view.name in PDF_TABLES for view in views)  # the first views
    return ReportContent(run, summary, views, pdf_tables, warnings, figures, appendix,
                         shown_sections(run))  # fmt: skip


def _route_content(info: RunInfo) -> ReportContent:
    run = load_route_run(info)
    views = route_views(run)
    figures = partial(route_run_figures, run)
    appendix = run_appendix(info, None)
    return ReportContent(
        info, route_summary(run), views, len(views), run.warnings, figures, appendix
    )


def _closed_loop_content(info: RunInfo) -> ReportContent:
    from homebench.report.closed_loop.report import (
        closed_loop_figures,
        closed_loop_summary,
        closed_loop_views,
        load_closed_loop_run,
    )

    run = load_closed_loop_run(info)
    views = closed_loop_views(run)
    figures = partial(closed_loop_figures, run)
    appendix = run_appendix(info, None)
    summary = closed_loop_summary(run)
    return ReportContent(info, summary, views, len(views) - 1, run.warnings, figures, appendix)


def load_content(
    run_dir: Path, max_goals: int | None = DEFAULT_MAX_GOALS, tables: RunTables | None = None
) -> ReportContent:
    """What the report of ``run_dir`` shows, by the run's kind (grid, route or closed-loop);
    a grid run's ``tables`` when the caller has them (see :func:`write_report`)."""
    info = read_run_info(run_dir)
    if info.kind == "route":
        return _route_content(info)
    if info.kind == "closed-loop":
        return _closed_loop_content(info)
    return _grid_content(info, max_goals, tables)


def _pdf_metadata(run: RunInfo) -> dict[str, str | datetime]:
    return {
        "Title": f"homebench report: {run.name}",
        "Creator": f"homebench {__version__}",
        "CreationDate": run.started,
        "ModDate": run.started,
    }


def _progress_shown(progress: bool) -> bool:
    """Whether to draw the progress bar: asked for, and stderr is a terminal."""
    return progress and sys.stderr.isatty()


def _write_figures(
    content: ReportContent,
    folder: Path,
    figure_files: FigureFiles,
    pages: Path | None,
    progress: bool,
) -> tuple[list[FigureEntry], list[Path], list[Path]]:
    """Draw every figure through ``figure_files``: its files under ``folder`` (PNG, PDF, SVG)
    and, with ``pages`` (a folder), the figures the documents show as captioned one-page PDFs
    in it. Their numbered entries, every figure file, and the page files in order."""
    folder.mkdir(parents=True, exist_ok=True)
    entries: list[FigureEntry] = []
    files: list[Path] = []
    page_files: list[Path] = []
    bar = tqdm(content.figures(), desc="report figures", unit="figure", file=sys.stderr,
               disable=not _progress_shown(progress))  # fmt: skip
    for stem, section, caption, fig in bar:
        page = None
        if content.in_documents(section):
            entry = FigureEntry(figure_paths(folder / stem)[0], section, caption,
                                len(entries) + 1)  # fmt: skip
            entries.append(entry)
            if pages is not None:
                page = (pages / f"figure-{entry.number:04d}.pdf", entry.numbered_caption)
                page_files.append(page[0])
        files += figure_files.save(fig, folder / stem, page)
        plt.close(fig)
    return entries, files, page_files


def _text_pages(path: Path, pages: Callable[[], Iterable[Figure]]) -> None:
    """Write the figures of text ``pages()`` makes (title, tables, appendix) as one PDF."""
    with PdfPages(path) as pdf:
        for fig in pages():
            pdf.savefig(fig)
            plt.close(fig)


def _front_pages(content: ReportContent) -> Iterator[Figure]:
    """The title page, the warnings and the tables of the PDF."""
    yield from title_pages(content.run, content.summary)
    yield from warning_pages(content.warnings) if content.warnings else []
    for view in content.views[: content.pdf_tables]:
        yield from table_pages(view)


def write_report(
    run_dir: Path,
    formats: Sequence[str] = ("pdf",),
    out_dir: Path | None = None,
    max_goals: int | None = DEFAULT_MAX_GOALS,
    *,
    progress: bool = True,
    tables: RunTables | None = None,
) -> ReportOutcome:
    """Write the report of ``run_dir`` (a grid or a route run) under ``out_dir`` (default
    ``run_dir/report``). ``tables``: a grid run's tables as the caller has just built them
    from this folder (:func:`~homebench.evaluation.results.build_tables` with the run
    config's metrics, as ``homebench run`` does), so that they are not read again.

    Always: ``tables/`` (grid: headline, summary, RR per goal, AHC per distance; route: per
    route length and per trial; as CSV, MD and TeX) and ``figures/`` (each figure as PNG, PDF
    and SVG); then ``report.pdf``, ``report.html`` and / or ``report.md`` as ``formats`` asks.
    Grid fields and AE maps are drawn for at most ``max_goals`` goals per condition (None:
    every goal). ``progress``: a progress bar over the figures on stderr (only when it is a
    terminal). Raises DataError when the folder is not a run or has no result at all; missing
    job or trial results otherwise become a warning page (and ``warnings``). A report whose
    inputs did not change since it was last written there is not written again
    (:mod:`~homebench.report.reuse`).
    """
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown:
        raise ValueError(f"unknown report format(s) {unknown}; choose from {FORMATS}")
    if max_goals is not None and max_goals < 1:
        raise ValueError(f"max_goals must be at least 1, got {max_goals}")
    folder = Path(out_dir) if out_dir is not None else Path(run_dir) / REPORT_FOLDER
    arguments = {"formats": sorted(set(formats)), "max_goals": max_goals,
                 "folder": str(folder.resolve())}  # fmt: skip
    key = reuse.report_key(Path(run_dir), folder, arguments)
    done = reuse.reusable(folder, key)
    if done is not None:
        return ReportOutcome(*done)
    reuse.forget(folder)
    outcome = _build_report(run_dir, formats, folder, max_goals, progress, tables)
    reuse.remember(folder, key, outcome.files, outcome.warnings)
    return outcome


def _build_report(
    run_dir: Path,
    formats: Sequence[str],
    folder: Path,
    max_goals: int | None,
    progress: bool,
    tables: RunTables | None,
) -> ReportOutcome:
    """Write the report (see :func:`write_report`) under ``folder``."""
    content = load_content(run_dir, max_goals, tables)
    run = content.run
    folder.mkdir(parents=True, exist_ok=True)
    table_files = write_views(content.views, folder / "tables")
    documents = []
    with report_style():
        if "pdf" in formats:
            path = folder / "report.pdf"
            figures, figure_files = _write_run_pdf(content, folder, path, progress)
            documents.append(path)
        else:
            with FigureFiles() as drawing:
                figures, figure_files, _ = _write_figures(
                    content, folder / "figures", drawing, None, progress
                )
    for suffix, render in (("md", markdown_report), ("html", html_report)):
        if suffix in formats:
            path = folder / f"report.{suffix}"
            text = render(run, content.summary, content.views, figures, content.warnings, folder,
                          content.appendix)  # fmt: skip
            write_text_atomic(path, text)
            documents.append(path)
    return ReportOutcome([*table_files, *figure_files, *documents], content.warnings)


def _write_run_pdf(
    content: ReportContent, folder: Path, path: Path, progress: bool
) -> tuple[list[FigureEntry], list[Path]]:
    """The PDF at ``path``: title page, warnings, the tables, the figures in their sections'
    order, the appendix; a bookmark to each (:func:`_outline`). Forked children
    (:class:`FigureFiles`) draw the pages while this process builds the next figure (the text
    pages first: they need no figure, so they are not left to the end); the pages are then
    joined into one document."""
    with tempfile.TemporaryDirectory(prefix="homebench-pages-") as temporary:
        pages = Path(temporary)
        front, back = pages / "front.pdf", pages / "back.pdf"
        with FigureFiles() as drawing:
            front_pages = partial(_front_pages, content)
            drawing.run("the title and table pages", partial(_text_pages, front, front_pages))
            back_pages = partial(appendix_pages, content.appendix)
            drawing.run("the appendix pages", partial(_text_pages, back, back_pages))
            figures, files, page_files = _write_figures(
                content, folder / "figures", drawing, pages, progress
            )
        parts = [front, *page_files, back]
        with atomic_write(path) as f:
            assemble_pdf(parts, f, _pdf_metadata(content.run), _outline(figures, len(parts)))
    return figures, files


def _outline(figures: Sequence[FigureEntry], n_parts: int) -> dict[int, str]:
    """The PDF's bookmarks (part index -> title) of its parts: the title and table pages,
    each section's first figure, the appendix."""
    outline = {0: FRONT_TITLE, n_parts - 1: BACK_TITLE}
    for k, entry in enumerate(figures):
        if k == 0 or figures[k - 1].section != entry.section:
            outline[k + 1] = entry.section
    return outline
