"""MkDocs hook: the reference pages generated from homebench's own lists at build time.

A hook rather than mkdocs-gen-files: one small file, no further plugin; MkDocs' own
``File.generated`` puts the pages into the build as if they were files under ``docs/``, so the
nav, the search and ``--strict``'s link checks treat them like the others, and nothing
generated is ever committed (it cannot drift from the code). The command reference is
mkdocs-click's (``docs/reference/cli.md``), the API mkdocstrings' (``docs/reference/api.md``).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))  # schema.py beside this file

import schema  # noqa: E402

#: Each generated page's introduction: where the page's content comes from in the code.
_SOURCE = "*Generated from the code at build time ({}): it cannot drift from what runs.*\n"


def methods_page() -> str:
    """Every registered method: the table of ``homebench methods --format md``, then each
    method's card (``homebench methods NAME --format md``)."""
    from homebench.methods import registry
    from homebench.methods.cards import (
        ENTRY_HEADER,
        ENTRY_PARAMETERS,
        card,
        card_markdown,
        listing_markdown,
        parameter_markdown,
    )

    cards = [card(name, cls) for name, cls in registry.available().items()]
    return "\n".join(
        [
            "# Methods",
            "",
            _SOURCE.format("`homebench.methods.cards`, as `homebench methods NAME` prints it"),
            "Each parameter's *standing*: **paper** (the paper's own parameter and default), "
            "**reading** (the paper is ambiguous or names no value; the note says which reading "
            "homebench implements) or **departure** (an opt-in option; the default is the "
            "paper's behaviour and the note says what the paper does).",
            "",
            listing_markdown(cards, registry.broken()),
            f"{ENTRY_HEADER}",
            "",
            *parameter_markdown(ENTRY_PARAMETERS),
            "",
            *(card_markdown(one) for one in cards),
        ]
    )


def _schema_page(title: str, intro: str, roots: list[type], source: str) -> str:
    """A page of the models reachable from ``roots``, each root followed by its module's
    docstring (its example and the reasons for its defaults)."""
    parts = [f"# {title}", "", _SOURCE.format(source), intro, ""]
    for model in schema.reachable(roots):
        parts.append(schema.section(model))
        if model in roots:
            module = model.__module__
            parts += [f"*From `{module}`:*", "", schema.module_doc(model), ""]
    return "\n".join(parts)


def config_page() -> str:
    """The run configs' keys: grid, route and closed-loop configs and what they hold."""
    from homebench.config import RunConfig
    from homebench.experiments.closed_loop.config import ClosedLoopConfig
    from homebench.experiments.route.config import RouteConfig

    intro = (
        "A config's `kind` chooses its schema: none (a grid run: [RunConfig](#runconfig)), "
        "`route` ([RouteConfig](#routeconfig)) or `closed-loop` "
        "([ClosedLoopConfig](#closedloopconfig)). Unknown keys are errors naming the closest "
        "known one; `homebench run CONFIG KEY=VALUE` overrides any key by its dotted path "
        "(`methods.0.params.n_rho=10`). A method entry's `params` are the method's parameters: "
        "see [Methods](methods.md)."
    )
    return _schema_page(
        "Run config reference",
        intro,
        [RunConfig, RouteConfig, ClosedLoopConfig],
        "the pydantic models of `homebench.config` and `homebench.experiments`",
    )


def manifest_page() -> str:
    """The manifest's keys (``data_manifests/*.yaml``)."""
    from homebench.data.manifest import Manifest

    intro = (
        "A manifest (`data_manifests/*.yaml`, or a path given to any `data` command or in a "
        "config's `databases`) says what a grid database is and how to get it: see "
        "[Databases](../guide/databases.md) for an annotated example."
    )
    return _schema_page(
        "Manifest reference", intro, [Manifest], "the pydantic models of `homebench.data.manifest`"
    )


def definitions_page() -> str:
    """The metrics and statistics, as a grid run's report defines them (default settings)."""
    from homebench.config import MetricsConfig
    from homebench.methods.cards import md_text
    from homebench.report.definitions import definitions

    lines = [
        "# Metrics and statistics",
        "",
        _SOURCE.format("`homebench.report.definitions`, the report's own definitions page"),
        "The definitions every report states, here for a config's default `metrics` section.",
        "",
    ]
    for heading, paragraphs in definitions(MetricsConfig()).items():
        lines += [f"## {heading}", "", *(f"{md_text(p)}\n" for p in paragraphs)]
    return "\n".join(lines)


def run_folder_records() -> str:
    """The run folder's tables' columns and its records' schemas (inserted into the run folder
    page, whose prose says what each file is for)."""
    from homebench.analysis import tables
    from homebench.evaluation import records, run_folder

    columns = {
        "tables/pairs.csv (its first columns; then those of a job's rows, PairRow)": tables.LEADING,
        "tables/goals.csv": tables.GOAL_COLUMNS,
        "tables/rr_starts.csv": tables.RR_START_COLUMNS,
    }
    lines = [
        _SOURCE.format("`homebench.evaluation.records`, `homebench.analysis.tables`"),
        f"The config as run is `{run_folder.CONFIG_FILE}`; of its keys, these may change "
        "between runs into one folder: "
        + ", ".join(f"`{k}`" for k in run_folder.EXECUTION_KEYS)
        + ".",
        "",
        "## Table columns",
        "",
        *(f"- `{name}`: " + ", ".join(f"`{c}`" for c in cols) for name, cols in columns.items()),
        "",
        "## Records",
        "",
        f"A job's result file (`jobs/`, format {records.RESULT_FORMAT}) is a "
        "[JobRecord](#jobrecord); `plan.json` a list of [PlanEntry](#planentry); each file "
        "of `failures/` a [FailureRecord](#failurerecord). Everything read back is checked "
        "against these schemas.",
        "",
    ]
    roots = [records.JobRecord, records.PlanEntry, records.FailureRecord]
    lines += [schema.section(cls, level=3) for cls in schema.reachable(roots)]
    return "\n".join(lines)


#: Generated page path (under docs/) -> the function that writes it.
PAGES: dict[str, Callable[[], str]] = {
    "reference/methods.md": methods_page,
    "reference/config.md": config_page,
    "reference/manifest.md": manifest_page,
    "reference/definitions.md": definitions_page,
}

#: What a hand-written page may insert: ``<!-- homebench: NAME -->`` -> the function writing it.
INSERTS: dict[str, Callable[[], str]] = {"run-folder-records": run_folder_records}


def on_files(files: Any, config: Any) -> Any:
    """MkDocs event: add the generated pages to the build."""
    from mkdocs.structure.files import File

    for path, make in PAGES.items():
        files.append(File.generated(config, path, content=make()))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """MkDocs event: replace each ``<!-- homebench: NAME -->`` by its generated text."""
    for name, make in INSERTS.items():
        marker = f"<!-- homebench: {name} -->"
        if marker in markdown:
            markdown = markdown.replace(marker, make())
    return markdown
