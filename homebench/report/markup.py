"""The HTML and Markdown reports: the title page's text, warnings, tables, the figure PNGs with
their numbered captions, and the appendix (definitions, config, environment)."""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from homebench.report.appendix import CONFIG_TITLE, DEFINITIONS_TITLE, ENVIRONMENT_TITLE, Appendix
from homebench.report.captions import numbered
from homebench.report.run_data import RunInfo
from homebench.report.tables import TableView, to_markdown


@dataclass(frozen=True)
class FigureEntry:
    """A figure of the documents: its PNG, the section heading it goes under, its caption and
    its number (the same in every format)."""

    path: Path
    section: str
    caption: str
    number: int

    @property
    def numbered_caption(self) -> str:
        return numbered(self.number, self.caption)


def _sections(figures: Sequence[FigureEntry]) -> dict[str, list[FigureEntry]]:
    """Figures grouped by section, sections in the order of their first figure."""
    groups: dict[str, list[FigureEntry]] = {}
    for entry in figures:
        groups.setdefault(entry.section, []).append(entry)
    return groups


def markdown_report(
    run: RunInfo, summary: dict[str, list[str]], views: Sequence[TableView],
    figures: Sequence[FigureEntry], warnings: list[str], folder: Path, appendix: Appendix,
) -> str:  # fmt: skip
    """The report as Markdown: ``summary`` (the title page), tables, figures with their
    captions, the appendix; figure links are relative to ``folder``."""
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
            link = entry.path.relative_to(folder).as_posix()
            lines += [f"![{entry.caption}]({link})", "", f"*{entry.numbered_caption}*", ""]
    return "\n".join(lines + _markdown_appendix(appendix))


def _markdown_appendix(appendix: Appendix) -> list[str]:
    lines = []
    if appendix.definitions:
        lines += [f"## {DEFINITIONS_TITLE}", ""]
        for heading, paragraphs in appendix.definitions.items():
            lines += [f"### {heading}", ""] + [line for p in paragraphs for line in (p, "")]
    lines += [f"## {CONFIG_TITLE}", "", "```json", *appendix.config, "```", ""]
    lines += [f"## {ENVIRONMENT_TITLE}", ""]
    for heading, section in appendix.environment.items():
        lines += [f"**{heading}**", "", *(f"- {line}" for line in section), ""]
    return lines


def html_report(
    run: RunInfo, summary: dict[str, list[str]], views: Sequence[TableView],
    figures: Sequence[FigureEntry], warnings: list[str], folder: Path, appendix: Appendix,
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
                f"<figcaption>{e(entry.numbered_caption)}</figcaption></figure>"
            )
    body += _html_appendix(appendix)
    style = (
        "body{font-family:sans-serif;max-width:1300px;margin:auto}"
        "table{border-collapse:collapse}td,th{padding:2px 8px;text-align:right}"
        "th{border-bottom:1px solid #444}img{max-width:100%}.warning{color:#b00}"
        "pre{white-space:pre-wrap}"
    )
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>homebench report: {e(run.name)}</title><style>{style}</style></head>\n"
        f"<body>\n" + "\n".join(body) + "\n</body></html>\n"
    )


def _html_appendix(appendix: Appendix) -> list[str]:
    e = html.escape
    body = []
    if appendix.definitions:
        body.append(f"<h2>{e(DEFINITIONS_TITLE)}</h2>")
        for heading, paragraphs in appendix.definitions.items():
            body.append(f"<h3>{e(heading)}</h3>" + "".join(f"<p>{e(p)}</p>" for p in paragraphs))
    body.append(f"<h2>{e(CONFIG_TITLE)}</h2><pre>{e(chr(10).join(appendix.config))}</pre>")
    body.append(f"<h2>{e(ENVIRONMENT_TITLE)}</h2>")
    for heading, section in appendix.environment.items():
        items = "".join(f"<li>{e(line)}</li>" for line in section)
        body.append(f"<h3>{e(heading)}</h3><ul>{items}</ul>")
    return body
