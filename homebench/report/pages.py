"""Text pages of the PDF report: the title page, the warning page and table pages."""

from __future__ import annotations

import textwrap
from typing import Any

from matplotlib.figure import Figure

from homebench.errors import HomebenchError
from homebench.methods import registry
from homebench.methods.params import paper_statement
from homebench.report.run_data import RunData, RunInfo
from homebench.report.style import new_figure
from homebench.report.tables import TableView

#: Characters per line of the text pages, and lines per page.
LINE_WIDTH = 120
PAGE_LINES = 36
#: Missing jobs listed on the warning pages.
MAX_WARNINGS = 200
#: Table rows per PDF page.
TABLE_ROWS = 24
#: Characters per line of a table header on the PDF pages (longer headers wrap).
HEADER_WIDTH = 16


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
            f"AHC bins: {ahc.bin_start_cm:g} to {ahc.bin_stop_cm:g} cm in steps of "
            f"{ahc.bin_step_cm:g} cm; pairs without estimate: {ahc.missing}",
            f"RR: step {rr.rh:g}, success radius {rr.success_radius:g}, max travel "
            f"{'half the perimeter' if rr.max_travel is None else f'{rr.max_travel:g}'} "
            "(grid units)",
            f"catchment: {'yes' if metrics.catchment else 'no'}",
        ],
        "Results": [
            f"{len(run.tables.pairs)} pairs from {n_jobs} job(s)",
            f"missing or corrupt job files: {missing}{' (see the next page)' if missing else ''}",
        ],
        "Environment": environment_lines(run),
    }


def _hanging(line: str) -> str:
    """The indent of a long ``line``'s continuation lines: its own indent and four spaces."""
    return line[: len(line) - len(line.lstrip())] + "    "


def _text_pages(title: str, lines: list[str]) -> list[Figure]:
    """``lines`` wrapped to LINE_WIDTH, PAGE_LINES per page, under ``title``."""
    wrapped = [
        part
        for line in lines
        for part in textwrap.wrap(line, LINE_WIDTH, subsequent_indent=_hanging(line)) or [""]
    ]
    pages = []
    for start in range(0, max(len(wrapped), 1), PAGE_LINES):
        fig = new_figure()
        heading = title if start == 0 else f"{title} (continued)"
        fig.text(0.06, 0.94, heading, fontsize=16, weight="bold", va="top")
        fig.text(0.06, 0.88, "\n".join(wrapped[start : start + PAGE_LINES]), fontsize=9,
                 va="top", linespacing=1.45)  # fmt: skip
        pages.append(fig)
    return pages


def title_pages(run: RunInfo, summary: dict[str, list[str]]) -> list[Figure]:
    """The title page: ``summary``'s sections (config, results, environment), continued if
    long."""
    lines = []
    for heading, section in summary.items():
        lines += [heading.upper(), *(f"    {line}" for line in section), ""]
    return _text_pages(f"homebench report: {run.name}", lines)


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


def table_pages(view: TableView) -> list[Figure]:
    """``view`` drawn as matplotlib tables, TABLE_ROWS rows per page."""
    text = view.text_frame()
    pages = []
    for start in range(0, max(len(text), 1), TABLE_ROWS):
        chunk = text.iloc[start : start + TABLE_ROWS]
        fig = new_figure()
        ax = fig.add_subplot()
        ax.axis("off")
        labels = ["\n".join(textwrap.wrap(c, HEADER_WIDTH)) for c in chunk.columns]
        table = ax.table(cellText=chunk.to_numpy().tolist(), colLabels=labels,
                         loc="upper center", cellLoc="right", colLoc="center")  # fmt: skip
        table.auto_set_font_size(False)
        table.set_fontsize(8)
        table.auto_set_column_width(list(range(len(chunk.columns))))
        table.scale(1.0, 1.5)
        header_lines = max(label.count("\n") + 1 for label in labels)
        for (row, column), cell in table.get_celld().items():
            if row == 0:
                cell.set_text_props(weight="bold")
                cell.set_height(cell.get_height() * header_lines)
            elif view.alignment()[column] == "left":
                cell.set_text_props(ha="left")
        part = f" ({start // TABLE_ROWS + 1})" if len(text) > TABLE_ROWS else ""
        fig.suptitle(view.title + part)
        pages.append(fig)
    return pages
