"""The HTML and Markdown reports: the title page's text, warnings, tables and the figure PNGs."""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from homebench.report.run_data import RunInfo
from homebench.report.tables import TableView, to_markdown


@dataclass(frozen=True)
class FigureEntry:
    """A written figure: its PNG, the section heading it goes under, its caption."""

    path: Path
    section: str
    caption: str


def _sections(figures: Sequence[FigureEntry]) -> dict[str, list[FigureEntry]]:
    """Figures grouped by section, sections in the order of their first figure."""
    groups: dict[str, list[FigureEntry]] = {}
    for entry in figures:
        groups.setdefault(entry.section, []).append(entry)
    return groups


def markdown_report(
    run: RunInfo, summary: dict[str, list[str]], views: Sequence[TableView],
    figures: Sequence[FigureEntry], warnings: list[str], folder: Path,
) -> str:  # fmt: skip
    """The report as Markdown: ``summary`` (the title page), tables and figures; figure links
    are relative to ``folder``."""
    lines = [f"# homebench report: {run.name}", ""]
    for heading, section in summary.items():
        lines += [f"**{heading}**", "", *(f"- {line}" for line in section), ""]
    if warnings:
        lines += ["## Warning: missing job results", "", *(f"- {w}" for w in warnings), ""]
    lines += ["## Tables", ""]
    for view in views:
        lines += [to_markdown(view)]
    for title, entries in _sections(figures).items():
        lines += [f"## {title}", ""]
        for entry in entries:
            lines += [f"![{entry.caption}]({entry.path.relative_to(folder).as_posix()})", ""]
    return "\n".join(lines)


def html_report(
    run: RunInfo, summary: dict[str, list[str]], views: Sequence[TableView],
    figures: Sequence[FigureEntry], warnings: list[str], folder: Path,
) -> str:  # fmt: skip
    """The report as one HTML page, as :func:`markdown_report`; figures are linked relative
    to ``folder``."""
    e = html.escape
    body = [f"<h1>homebench report: {e(run.name)}</h1>"]
    for heading, section in summary.items():
        items = "".join(f"<li>{e(line)}</li>" for line in section)
        body.append(f"<h3>{e(heading)}</h3><ul>{items}</ul>")
    if warnings:
        items = "".join(f"<li>{e(w)}</li>" for w in warnings)
        body.append(f'<h2 class="warning">Warning: missing job results</h2><ul>{items}</ul>')
    body.append("<h2>Tables</h2>")
    for view in views:
        table = view.text_frame().to_html(index=False, border=0, classes="table")
        body.append(f"<h3>{e(view.title)}</h3>{table}")
    for title, entries in _sections(figures).items():
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
