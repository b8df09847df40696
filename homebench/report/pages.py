"""Text pages of the PDF report: the title page, the warning page, table pages and the
appendix (definitions, config, environment)."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.table import Table

from homebench.errors import HomebenchError
from homebench.methods import registry
from homebench.methods.params import paper_statement
from homebench.report.appendix import CONFIG_TITLE, DEFINITIONS_TITLE, ENVIRONMENT_TITLE, Appendix
from homebench.report.definitions import bands_text
from homebench.report.run_data import RunData, RunInfo
from homebench.report.style import PAGE_SIZE, new_figure, stop_layout
from homebench.report.tables import AHC_MEANINGS, TableView

#: Characters per line of the text pages, and lines per page.
LINE_WIDTH = 120
PAGE_LINES = 36
#: Missing jobs listed on the warning pages.
MAX_WARNINGS = 200
#: Table rows per PDF page.
TABLE_ROWS = 24
#: Characters per line of a table header on the PDF pages (longer headers wrap).
HEADER_WIDTH = 16
#: Font size of the table cells (points) unless shrunk to fit the page's width.
TABLE_FONT_SIZE = 8
#: Where a table page's table goes (figure fraction: left, bottom, width, height; the bottom
#: rises for long notes); its notes go below.
TABLE_AREA = (0.03, 0.1, 0.94, 0.82)
#: Font size of a table's notes (points), the height of a note line and the space below the
#: notes (inches).
NOTE_FONT_SIZE = 7
NOTE_LINE_HEIGHT = NOTE_FONT_SIZE * 1.25 / 72
NOTE_MARGIN = 0.3
#: Share of the room a table shrunk to fit is given (room for rounding of text widths).
TABLE_FIT = 0.97


def _goals_text(goals: Any) -> str:
    if isinstance(goals, list):
        return ", ".join(f"({i}, {j})" for i, j in goals)
    if isinstance(goals, dict):
        return f"{goals.get('random')} random (seed {goals.get('seed')})"
    return str(goals)


def _currents_text(currents: Any) -> str:
    if isinstance(currents, dict):
        return (
            f"{currents.get('min_distance', 0):g} to {currents.get('max_distance', 'inf'):g} m "
            "from the goal"
        )
    return str(currents)


def _rotation_text(rotation: Any) -> str:
    if isinstance(rotation, dict) and rotation.get("enabled"):
        return f"yes, random whole columns (seed {rotation.get('seed')})"
    return "no"


def _method_text(entry: dict[str, Any]) -> str:
    """ "label: method, <how it stands to its paper>" (parameters listed when the method is not
    installed here to tell)."""
    label = entry.get("label") or entry["method"]
    params = entry.get("params", {})
    swept = f"; swept: {', '.join(sorted(entry['grid']))}" if entry.get("grid") else ""
    try:
        statement = paper_statement(registry.get(entry["method"]), params)
    except HomebenchError:
        listed = ", ".join(f"{k}={v!r}" for k, v in sorted(params.items()))
        statement = f"parameters {listed}" if listed else "its defaults"
    return f"{label}: {entry['method']}, {statement}{swept}"


def run_lines(run: RunInfo) -> list[str]:
    """The title page's "Run" section: name, output folder, config file, start."""
    return [
        f"name: {run.name}",
        f"output: {run.config.get('output')}",
        f"config file: {run.environment.get('config_file')}",
        f"started: {run.started.strftime('%Y-%m-%d %H:%M:%S %Z')}",
    ]


def environment_lines(run: RunInfo) -> list[str]:
    """The title page's "Environment" section: host and package versions."""
    env = run.environment
    return [
        f"host: {env.get('host')} ({env.get('platform')}, {env.get('cpu_count')} CPUs)",
        "versions: " + ", ".join(f"{k} {v}" for k, v in env.get("versions", {}).items()),
    ]


def run_summary(run: RunData) -> dict[str, list[str]]:
    """A grid run's title page sections: heading -> lines (config, environment, results)."""
    config, metrics = run.config, run.metrics
    ahc, rr = metrics.ahc, metrics.return_ratio
    databases = [f"{alias}: {run.database_label(alias)}" for alias in config.get("databases", {})]
    missing = len(run.tables.missing_jobs)
    n_jobs = run.tables.pairs.groupby(["condition", "method", "goal_i", "goal_j"]).ngroups
    return {
        "Run": run_lines(run),
        "Experiment": [
            *(f"database {line}" for line in databases),
            f"conditions (current-goal): {', '.join(config.get('conditions', []))}",
            f"goals: {_goals_text(config.get('goals'))}",
            f"currents: {_currents_text(config.get('currents'))}",
            f"rotated current views: {_rotation_text(config.get('rotate_current'))}",
            *(f"method {_method_text(entry)}" for entry in config.get("methods", [])),
        ],
        "Metrics": [
            f"AHC: {AHC_MEANINGS[ahc.definition]}; bins: {ahc.bin_start_cm:g} to "
            f"{ahc.bin_stop_cm:g} cm in steps of {ahc.bin_step_cm:g} cm; pairs without "
            f"estimate: {ahc.missing}",
            f"distance bands: {bands_text(metrics.band_edges_m)}",
            f"RR (grid units): step {rr.rh:g}, success radius {rr.success_radius:g}, max travel "
            f"{'half the perimeter' if rr.max_travel is None else f'{rr.max_travel:g}'}; "
            f"no_estimate: {rr.no_estimate}",
            f"catchment: {'yes' if metrics.catchment else 'no'}",
            f"what the metrics and intervals mean: '{DEFINITIONS_TITLE}', after the figures",
        ],
        "Results": [
            f"{len(run.tables.pairs)} pairs from {n_jobs} job(s)",
            f"missing or corrupt job files: {missing}{' (see the next page)' if missing else ''}",
        ],
        "Environment": environment_lines(run),
    }


@dataclass(frozen=True)
class TextLayout:
    """How text pages set their lines: ``width`` characters per line, ``lines`` per column,
    ``columns`` per page, in a font of ``fontsize`` points and ``family``."""

    width: int
    lines: int
    columns: int
    fontsize: float
    family: str


PROSE = TextLayout(LINE_WIDTH, PAGE_LINES, 1, 9, "sans-serif")
#: JSON: short lines in a fixed-width font, two columns a page.
CODE = TextLayout(80, 52, 2, 7, "monospace")


def _hanging(line: str, extra: str) -> str:
    """The indent of a long ``line``'s continuation lines: its own indent and ``extra``."""
    return line[: len(line) - len(line.lstrip())] + extra


def _text_pages(
    title: str, lines: list[str], layout: TextLayout = PROSE, hang: str = "    "
) -> list[Figure]:
    """``lines`` wrapped to the layout's width (continuation lines indented by ``hang`` more
    than their line), as many pages as they fill, under ``title``."""
    wrapped = [
        part
        for line in lines
        for part in textwrap.wrap(
            line, layout.width, subsequent_indent=_hanging(line, hang), break_on_hyphens=False
        )
        or [""]
    ]
    while wrapped and not wrapped[-1].strip():
        wrapped.pop()  # trailing blank lines would start a page of their own
    per_page = layout.lines * layout.columns
    pages = []
    for start in range(0, max(len(wrapped), 1), per_page):
        fig = new_figure()
        heading = title if start == 0 else f"{title} (continued)"
        fig.text(0.06, 0.94, heading, fontsize=16, weight="bold", va="top")
        for column in range(layout.columns):
            first = start + column * layout.lines
            fig.text(0.06 + column * 0.88 / layout.columns, 0.88,
                     "\n".join(wrapped[first : first + layout.lines]), fontsize=layout.fontsize,
                     family=layout.family, va="top", linespacing=1.45)  # fmt: skip
        pages.append(fig)
    return pages


def section_lines(sections: dict[str, list[str]], gap: bool = False) -> list[str]:
    """Headed sections as text lines: each heading in capitals, its lines indented below;
    ``gap``: a blank line between the lines (paragraphs)."""
    lines = []
    for heading, section in sections.items():
        lines.append(heading.upper())
        for line in section:
            lines += [f"    {line}", *([""] if gap else [])]
        lines += [] if gap else [""]
    return lines


def title_pages(run: RunInfo, summary: dict[str, list[str]]) -> list[Figure]:
    """The title page: ``summary``'s sections (config, results, environment), continued if
    long."""
    return _text_pages(f"homebench report: {run.name}", section_lines(summary))


def appendix_pages(appendix: Appendix) -> list[Figure]:
    """The definitions of the metrics and statistics (if any), the resolved config, the
    environment and the data sets' checksums."""
    pages = []
    if appendix.definitions:
        lines = section_lines(appendix.definitions, gap=True)
        pages += _text_pages(DEFINITIONS_TITLE, lines, hang="")
    pages += _text_pages(CONFIG_TITLE, appendix.config, CODE)
    pages += _text_pages(ENVIRONMENT_TITLE, section_lines(appendix.environment))
    return pages


def warning_pages(warnings: list[str]) -> list[Figure]:
    """The missing jobs, at most MAX_WARNINGS of them listed."""
    shown = warnings[:MAX_WARNINGS]
    more = len(warnings) - len(shown)
    lines = [
        "This run is incomplete: the jobs below have no valid result file (missing, corrupt or",
        "of another job). Their results are absent from every table and figure of this report.",
        "",
        *shown,
        *([f"... and {more} more"] if more else []),
    ]
    return _text_pages("Warning: missing job results", lines)


def _fit_table(table: Table, ax: Axes) -> None:
    """Shrink ``table`` (font, then row heights) until it lies within ``ax``."""
    renderer = ax.get_figure(root=True).canvas.get_renderer()
    size = TABLE_FONT_SIZE
    for _ in range(3):  # column widths follow the font only roughly (padding)
        width = table.get_window_extent(renderer).width
        if width <= ax.bbox.width:
            break
        size *= TABLE_FIT * ax.bbox.width / width
        table.set_fontsize(size)
    height = table.get_window_extent(renderer).height
    if height > ax.bbox.height:
        table.scale(1.0, TABLE_FIT * ax.bbox.height / height)


def _table_area(note_lines: int) -> tuple[float, float, float, float]:
    """TABLE_AREA, its bottom raised to leave room for ``note_lines`` lines of notes."""
    left, bottom, width, height = TABLE_AREA
    low = max(bottom, (note_lines * NOTE_LINE_HEIGHT + NOTE_MARGIN) / PAGE_SIZE[1])
    return left, low, width, bottom + height - low


def table_pages(view: TableView) -> list[Figure]:
    """``view`` drawn as matplotlib tables, TABLE_ROWS rows per page, shrunk to fit the page;
    marked cells in bold, the view's note lines under the table."""
    text, marked, alignment = view.text_frame(), view.mark_mask(), view.alignment()
    notes = [part for line in view.note_lines("Bold")
             for part in textwrap.wrap(line, LINE_WIDTH + 40)]  # fmt: skip
    area = _table_area(len(notes))
    pages = []
    for start in range(0, max(len(text), 1), TABLE_ROWS):
        chunk = text.iloc[start : start + TABLE_ROWS]
        fig = new_figure()
        stop_layout(fig)  # the table is placed by hand, inside its area
        ax = fig.add_axes(area)
        ax.axis("off")
        labels = ["\n".join(textwrap.wrap(c, HEADER_WIDTH)) for c in chunk.columns]
        table = ax.table(cellText=chunk.to_numpy().tolist(), colLabels=labels,
                         loc="upper center", cellLoc="right", colLoc="center")  # fmt: skip
        table.auto_set_font_size(False)
        table.set_fontsize(TABLE_FONT_SIZE)
        table.auto_set_column_width(list(range(len(chunk.columns))))
        table.scale(1.0, 1.5)
        header_lines = max(label.count("\n") + 1 for label in labels)
        for (row, column), cell in table.get_celld().items():
            if row == 0:
                cell.set_text_props(weight="bold")
                cell.set_height(cell.get_height() * header_lines)
                continue
            if alignment[column] == "left":
                cell.set_text_props(ha="left")
            if marked[start + row - 1, column]:
                cell.set_text_props(weight="bold")
        _fit_table(table, ax)
        part = f" ({start // TABLE_ROWS + 1})" if len(text) > TABLE_ROWS else ""
        fig.suptitle(view.title + part)
        fig.text(area[0], area[1] - 0.01, "\n".join(notes), fontsize=NOTE_FONT_SIZE, va="top")
        pages.append(fig)
    return pages
