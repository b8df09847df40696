"""The HTML and Markdown reports: the title page's text, warnings, tables and the figure PNGs."""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from homebench.report.pages import run_summary
from homebench.report.run_data import RunData
from homebench.report.tables import TableView, to_markdown


@dataclass(frozen=True)
class FigureEntry:
    """A written figure: its PNG, the condition it belongs to (None: the whole run), caption."""

    path: Path
    condition: str | None
    caption: str


def _sections(run: RunData, figures: Sequence[FigureEntry]) -> list[tuple[str, list[FigureEntry]]]:
    """Figures grouped by condition, in the run's condition order."""
    groups = []
    for condition in [*run.conditions, None]:
        chosen = [f for f in figures if f.condition == condition]
        if chosen:
            title = "Run" if condition is None else run.condition_title(condition)
            groups.append((title, chosen))
    return groups


def markdown_report(
    run: RunData, views: Sequence[TableView], figures: Sequence[FigureEntry], warnings: list[str],
    folder: Path,
) -> str:  # fmt: skip
    """The report as Markdown; figure links are relative to ``folder``."""
    lines = [f"# homebench report: {run.name}", ""]
    for heading, section in run_summary(run).items():
        lines += [f"**{heading}**", "", *(f"- {line}" for line in section), ""]
    if warnings:
        lines += ["## Warning: missing job results", "", *(f"- {w}" for w in warnings), ""]
    lines += ["## Tables", ""]
    for view in views:
        lines += [to_markdown(view)]
    for title, entries in _sections(run, figures):
        lines += [f"## {title}", ""]
        for entry in entries:
            lines += [f"![{entry.caption}]({entry.path.relative_to(folder).as_posix()})", ""]
    return "\n".join(lines)


def html_report(
    run: RunData, views: Sequence[TableView], figures: Sequence[FigureEntry], warnings: list[str],
    folder: Path,
) -> str:  # fmt: skip
    """The report as one HTML page; figures are linked relative to ``folder``."""
    e = html.escape
    body = [f"<h1>homebench report: {e(run.name)}</h1>"]
    for heading, section in run_summary(run).items():
        items = "".join(f"<li>{e(line)}</li>" for line in section)
        body.append(f"<h3>{e(heading)}</h3><ul>{items}</ul>")
    if warnings:
        items = "".join(f"<li>{e(w)}</li>" for w in warnings)
        body.append(f'<h2 class="warning">Warning: missing job results</h2><ul>{items}</ul>')
    body.append("<h2>Tables</h2>")
    for view in views:
        table = view.text_frame().to_html(index=False, border=0, classes="table")
        body.append(f"<h3>{e(view.title)}</h3>{table}")
    for title, entries in _sections(run, figures):
        body.append(f"<h2>{e(title)}</h2>")
        for entry in entries:
            src = e(entry.path.relative_to(folder).as_posix())
            body.append(
                f'<figure><img src="{src}" alt="{e(entry.caption)}">'
                f"<figcaption>{e(entry.caption)}</figcaption></figure>"
            )
    style = (
        "body{font-family:sans-serif;max-width:1300px;margin:auto}"
        "table{border-collapse:collapse}td,th{padding:2px 8px;text-align:right}"
        "th{border-bottom:1px solid #444}img{max-width:100%}.warning{color:#b00}"
    )
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>homebench report: {e(run.name)}</title><style>{style}</style></head>\n"
        f"<body>\n" + "\n".join(body) + "\n</body></html>\n"
    )
