"""``homebench report``: tables, figures and the PDF (plus HTML / Markdown) of a run folder.

Everything comes from the run folder alone, and the output is reproducible: the PDF's dates
are the run's start (environment.json), figure files carry no date, so two reports of the same
run are byte-identical.

The PDF: the title page, warnings, tables, the figures (each with a numbered caption below it)
and an appendix: the definitions of the metrics and statistics, the resolved config, the
environment and the data sets' checksums. A run over more than MAX_DETAILED_CONDITIONS
conditions (style x condition) shows overview heat maps and the overview figures instead of
every condition's figures, whose files are still written.
"""

from __future__ import annotations

import itertools
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from datetime import datetime
from functools import partial
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from tqdm import tqdm

from homebench import __version__
from homebench.errors import DataError
from homebench.evaluation.results import RunTables
from homebench.fileio import atomic_write, write_text_atomic
from homebench.report import reuse
from homebench.report.appendix import Appendix, run_appendix
from homebench.report.figure_data import (
    condition_goals,
    goal_panels,
    image_describe_times,
    pick_goals,
)
from homebench.report.figure_files import FigureFiles, assemble_pdf
from homebench.report.grid_figures import AE_MAX_DEG, ae_figure, field_figure, grid_pages
from homebench.report.heatmaps import OVERVIEW_SECTION, heatmap_columns, heatmap_figures
from homebench.report.markup import FigureEntry, html_report, markdown_report
from homebench.report.metric_figures import (
    ConditionPanel,
    RRPanel,
    ahc_figure,
    ahc_pages,
    ahc_range,
    rr_figure,
    rr_pages,
    timing_figure,
)
from homebench.report.pages import (
    appendix_pages,
    run_summary,
    table_pages,
    title_pages,
    warning_pages,
)
from homebench.report.route_report import (
    load_route_run,
    route_run_figures,
    route_summary,
    route_views,
)
from homebench.report.run_data import RunData, RunInfo, grid_run, read_run_info
from homebench.report.style import MethodStyle, figure_paths, method_styles, report_style
from homebench.report.tables import TableView, report_views, run_order, write_views

FORMATS = ("pdf", "html", "md")
#: Section of the figures of all conditions side by side (AHC, RR).
METRICS_SECTION = "All conditions"
REPORT_FOLDER = "report"
#: A grid run with more conditions (style x condition) than this gets overview heat maps in
#: its documents instead of every condition's figures.
MAX_DETAILED_CONDITIONS = 6


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


def _goal_note(shown: int, total: int) -> str:
    return "" if shown == total else f" ({shown} of {total} goals shown)"


def _page_note(k: int, n: int) -> str:
    return f", part {k} of {n}" if n > 1 else ""


def _styles(run: RunData) -> dict[str, MethodStyle]:
    """The look of each method label of the run, in the config's order (the drawing order)."""
    return method_styles(run_order(run).methods_of(run.tables.pairs["method"]))


def _condition_figures(
    run: RunData, condition: str, max_goals: int | None
) -> Iterator[tuple[str, str, Figure]]:
    """(file stem, caption, figure) of one condition: the home-vector fields (the paper's
    Figure 7) and AE maps (Figure 8) of every goal (or ``max_goals`` of them), a few goals per
    figure, then the time per call."""
    tables = run.tables
    styles = _styles(run)
    where = run.condition_title(condition)
    pairs = tables.pairs[tables.pairs["condition"] == condition]
    goals = condition_goals(tables.pairs, condition)
    shown = pick_goals(goals, max_goals)
    note = _goal_note(len(shown), len(goals))
    order = list(styles)
    panels = [(goal, goal_panels(pairs, run.metrics, condition, goal, order)) for goal in shown]
    chunks = grid_pages(panels)
    for k, chunk in enumerate(chunks, start=1):
        listed = ", ".join(goal.text for goal, _ in chunk)
        caption = (
            f"Home-vector fields, {where}, goals {listed}{note}{_page_note(k, len(chunks))}. "
            "Arrows: estimated home direction from each current position, in the method's "
            "colour where the return-ratio trial from there succeeds, dark where it fails; "
            "red square: goal; x: no estimate."
        )
        yield f"{condition}_fields_{k}", caption, field_figure(chunk, styles)
    for k, chunk in enumerate(chunks, start=1):
        listed = ", ".join(goal.text for goal, _ in chunk)
        caption = (
            f"Angular error (AE) per current position, {where}, goals {listed}{note}"
            f"{_page_note(k, len(chunks))}. Fixed scale 0 to {AE_MAX_DEG:g} deg in every map "
            "(larger errors in the top colour); star: goal; hatched: no estimate."
        )
        yield f"{condition}_ae_{k}", caption, ae_figure(chunk)
    caption = (
        f"Time per call, {where}: describe per image, home per pair (log scale; box: "
        "quartiles, line: median)."
    )
    describe = image_describe_times(pairs)
    yield f"{condition}_timing", caption, timing_figure(describe, pairs, styles)


def _styles_of(frame: pd.DataFrame) -> list[str]:
    """The swept styles of ``frame``'s rows, sorted; [""] without a sweep."""
    if "style" not in frame.columns or frame["style"].isna().all():
        return [""]
    return sorted(str(s) for s in frame["style"].dropna().unique())


def _of_style(frame: pd.DataFrame, style: str) -> pd.DataFrame:
    return frame[frame["style"] == style] if style else frame


def _metric_panels(run: RunData) -> tuple[list[ConditionPanel], list[RRPanel], list[str]]:
    """The AHC and RR panels of every condition (per swept style) in the config's order, and
    the long title of each."""
    tables = run.tables
    ahc_panels, rr_panels, titles = [], [], []
    for condition in run.conditions:
        ahc = tables.ahc[tables.ahc["condition"] == condition]
        goals = tables.goals[tables.goals["condition"] == condition]
        summary = tables.summary[tables.summary["condition"] == condition]
        for style in _styles_of(ahc):
            title = f"{condition} {style}".strip()
            ahc_panels.append(ConditionPanel(title, _of_style(ahc, style)))
            rr_panels.append(RRPanel(title, _of_style(goals, style), _of_style(summary, style)))
            titles.append(f"{run.condition_title(condition)}{f', {style}' if style else ''}")
    return ahc_panels, rr_panels, titles


def _lettered(chunks: Sequence[Sequence[object]], titles: Sequence[str]) -> Iterator[str]:
    """Per page of ``chunks``: its part note and its panels' ``titles`` lettered (a), (b)..."""
    start = 0
    for k, chunk in enumerate(chunks, start=1):
        page = titles[start : start + len(chunk)]
        start += len(chunk)
        listed = "; ".join(f"({chr(ord('a') + n)}) {t}" for n, t in enumerate(page))
        yield f"{_page_note(k, len(chunks))}: {listed}"


def _metric_figures(run: RunData) -> Iterator[tuple[str, str, Figure]]:
    """(file stem, caption, figure): AHC against distance (the paper's Figure 9) and RR per
    goal (Figure 10), every condition side by side, on one scale each."""
    styles = _styles(run)
    ahc_panels, rr_panels, titles = _metric_panels(run)
    limits = ahc_range(run.tables.ahc)
    chunks = ahc_pages(ahc_panels)
    for k, (chunk, panels) in enumerate(zip(chunks, _lettered(chunks, titles), strict=True)):
        caption = (
            f"AHC against the distance between current and goal position{panels}. Lines: AHC "
            "per distance bin; bands: 95 % goal-bootstrap CI; top axis: pairs per bin; AHC "
            f"axis {limits[0]:g} to {limits[1]:g} in every panel."
        )
        yield f"ahc_{k + 1}", caption, ahc_figure(chunk, styles, limits)
    chunks = rr_pages(rr_panels)
    for k, (chunk, panels) in enumerate(zip(chunks, _lettered(chunks, titles), strict=True)):
        caption = (
            f"Return ratio (RR) per goal{panels}. Right of the dotted line: each method's mean "
            "RR over the goals with its 95 % goal-bootstrap CI; n/a: the field does not cover "
            "the grid."
        )
        yield f"rr_{k + 1}", caption, rr_figure(chunk, styles)


def _grid_figures(run: RunData, max_goals: int | None) -> Iterator[tuple[str, str, str, Figure]]:
    """Every condition's figures, grouped by condition in the config's order, then AHC and RR
    of all conditions side by side."""
    for condition in run.conditions:
        section = run.condition_title(condition)
        for stem, caption, fig in _condition_figures(run, condition, max_goals):
            yield stem, section, caption, fig
    for stem, caption, fig in _metric_figures(run):
        yield stem, METRICS_SECTION, caption, fig


def _grid_content(
    info: RunInfo, max_goals: int | None, tables: RunTables | None = None
) -> ReportContent:
    run = grid_run(info, tables)
    warnings = list(run.tables.missing_jobs)
    if run.tables.pairs.empty:
        shown = "; ".join(warnings[:3]) + (" ..." if len(warnings) > 3 else "")
        raise DataError(f"{run.run_dir}: no job results to report on (missing: {shown})")
    views = report_views(run.tables, run_order(run))
    summary = run_summary(run)
    appendix = run_appendix(run, run.metrics.catchment)
    n_columns = len(heatmap_columns(run.tables.summary, run.conditions))
    if n_columns <= MAX_DETAILED_CONDITIONS:
        figures = partial(_grid_figures, run, max_goals)
        return ReportContent(run, summary, views, 1, warnings, figures, appendix)
    summary["Figures"] = [
        f"{n_columns} conditions (more than {MAX_DETAILED_CONDITIONS}): this report shows "
        f"overview heat maps (method x condition: AHC, RR, mean AE) and the figures of "
        f"'{METRICS_SECTION}'; every condition's figures are in the figures folder (PNG, PDF, "
        "SVG)"
    ]
    seeds_pooled = run.tables.pairs["seed"].nunique(dropna=False) > 1
    ordered = run_order(run).sort(run.tables.summary)
    heatmaps = partial(heatmap_figures, ordered, run.conditions, seeds_pooled)
    figures = partial(_chained, [heatmaps, partial(_grid_figures, run, max_goals)])
    shown = frozenset({OVERVIEW_SECTION, METRICS_SECTION})
    return ReportContent(run, summary, views, 1, warnings, figures, appendix, shown)


def _chained(sources: list[FigureSource]) -> Iterator[tuple[str, str, str, Figure]]:
    """The figures of each of ``sources`` in turn."""
    return itertools.chain.from_iterable(source() for source in sources)


def _route_content(info: RunInfo) -> ReportContent:
    run = load_route_run(info)
    views = route_views(run)
    figures = partial(route_run_figures, run)
    appendix = run_appendix(info, None)
    return ReportContent(
        info, route_summary(run), views, len(views), run.warnings, figures, appendix
    )


def _closed_loop_content(info: RunInfo) -> ReportContent:
    from homebench.report.closed_loop_report import (
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
    run_dir: Path, max_goals: int | None = None, tables: RunTables | None = None
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
    max_goals: int | None = None,
    *,
    progress: bool = True,
    tables: RunTables | None = None,
) -> ReportOutcome:
    """Write the report of ``run_dir`` (a grid or a route run) under ``out_dir`` (default
    ``run_dir/report``). ``tables``: a grid run's tables as the caller has just built them
    from this folder (:func:`~homebench.evaluation.results.build_tables` with the run
    config's metrics, as ``homebench run`` does), so that they are not read again.

    Always: ``tables/`` (grid: summary, RR per goal, AHC per distance; route: per route length
    and per trial; as CSV, MD and TeX) and ``figures/`` (each figure as PNG, PDF and SVG);
    then ``report.pdf``, ``report.html`` and / or ``report.md`` as ``formats`` asks. Grid
    fields and AE maps are drawn for at most ``max_goals`` goals per condition. ``progress``:
    a progress bar over the figures on stderr (only when it is a terminal). Raises DataError
    when the folder is not a run or has no result at all; missing job or trial results
    otherwise become a warning page (and ``warnings``). A report whose inputs did not change
    since it was last written there is not written again (:mod:`~homebench.report.reuse`).
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
    order, the appendix. Forked children (:class:`FigureFiles`) draw the pages while this
    process builds the next figure (the text pages first: they need no figure, so they are not
    left to the end); the pages are then joined into one document."""
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
        with atomic_write(path) as f:
            assemble_pdf([front, *page_files, back], f, _pdf_metadata(content.run))
    return figures, files
