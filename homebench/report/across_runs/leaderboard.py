"""``homebench leaderboard``: one metric of several runs' methods, condition by condition.

Rows are method labels (in label order), columns conditions (``style/condition`` in a style
sweep) of one world: where runs hold a condition of the same name on other databases, each
world gets its own column, ``condition @ world`` (:mod:`homebench.analysis.worlds`). A column
that not every run holds names the runs that do, ``quick: original-day`` (runs of other
worlds are not told apart by their conditions' names), with a note saying that a column
named by its condition alone is in every run. Each cell
is ``estimate [lo, hi]`` from its run's summary table (the 95 % goal-bootstrap interval), ``--``
where there is none (a method that gives no home direction has no direction metric). A metric
that a method can flatter by abstaining is followed, where the method gave no estimate for some
pairs, by what shows it (:data:`BOARD_METRICS`): an AHC cell reads ``AHC [lo, hi] / other AHC /
no estimate [%]``, the AHC with a missing estimate as 90 deg beside the paper's (or the other
way round) and the share of pairs without an estimate; a mean AE cell adds the share. The
title names the runs' AHC definition; runs that define the AHC otherwise
(:class:`~homebench.config.AhcConfig`) are not ranked on an AHC together, nor runs whose
return-ratio walks differ (:class:`~homebench.config.ReturnRatioConfig`) on the RR.

A method label found in several runs becomes one row per run, ``run: label``, when its method
or parameters differ between them or when two of them hold it under the same column; otherwise
its runs' cells share one row. The best estimate of each column as shown (largest AHC or RR,
smallest mean AE or share without an estimate; ties alike) is marked ``*``. The optional index
page lists the table and links each run's report.
"""

from __future__ import annotations

import html
import json
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
from pydantic import BaseModel

from homebench.analysis.worlds import world_keys, world_label
from homebench.config import AhcConfig, ReturnRatioConfig
from homebench.errors import DataError
from homebench.fileio import write_text_atomic
from homebench.report.across_runs.run_set import load_grid_runs, missing_results, run_labels
from homebench.report.run_data import RunData
from homebench.report.tables import (
    MISSING_TEXT,
    SUMMARY_COLUMNS,
    TableView,
    ahc_header,
    few_goals_note,
    make_view,
)

BEST = " *"
#: Between a cell's metric and what follows it.
COMPANION_SEPARATOR = " / "


@dataclass(frozen=True)
class BoardMetric:
    """A metric of the board (a summary column; header, digits and scale of
    :data:`~homebench.report.tables.SUMMARY_COLUMNS`): whether larger is better, and the
    summary columns its cells show after it (without their intervals)."""

    larger_better: bool
    companions: tuple[str, ...] = ()


BOARD_METRICS = {
    "ahc": BoardMetric(True, ("ahc_missing90", "no_estimate_share")),
    "ahc_missing90": BoardMetric(True, ("ahc", "no_estimate_share")),
    "rr": BoardMetric(True),
    "mean_ae_deg": BoardMetric(False, ("no_estimate_share",)),
    "no_estimate_share": BoardMetric(False),
}
#: Metrics that depend on how the runs define the AHC.
AHC_METRICS = ("ahc", "ahc_missing90")
#: Report documents an index page links, most browsable first.
REPORT_FILES = ("report.html", "report.pdf", "report.md")


@dataclass(frozen=True)
class Leaderboard:
    """The table and the runs it was drawn from (labels and folders, in order); ``warnings``:
    one line per job of theirs without a result (its goals are not in the run's cells)."""

    view: TableView
    labels: list[str]
    run_dirs: list[Path]
    warnings: list[str]


def method_configs(run: RunData) -> dict[str, str]:
    """Each method label of ``run``'s config (grid points included) -> its method name and
    parameters as canonical JSON."""
    return {
        label: json.dumps([name, params], sort_keys=True, default=str)
        for label, name, params in run.settings.method_points()
    }


def _cells(runs: Sequence[RunData], labels: Sequence[str], columns: Sequence[str]) -> pd.DataFrame:
    """One row per (run, summary row): run, method, column, world, the summary's ``columns``
    (the metric, its bounds and its companions), config."""
    records = []
    for label, run in zip(labels, runs, strict=True):
        configs = method_configs(run)
        pairs = run.tables.pairs
        worlds = world_keys(pairs.assign(style=pairs["style"].astype("object")),
                            ["style", "condition"])  # fmt: skip
        for row in run.tables.summary.to_dict("records"):
            style = row.get("style")
            swept = isinstance(style, str)
            records.append({
                "run": label,
                "method": row["method"],
                "column": f"{style}/{row['condition']}" if swept else row["condition"],
                "world": worlds.get((style if swept else "", row["condition"]), ""),
                **{name: row.get(name, math.nan) for name in columns},
                "config": configs.get(row["method"], ""),
            })  # fmt: skip
    cells = pd.DataFrame(records)
    cells["column"] = _world_columns(cells)
    return cells


def _world_columns(cells: pd.DataFrame) -> list[str]:
    """Each cell's column: its condition column, with ``@ world`` where runs hold that
    condition on other databases (the full world key where two short labels coincide)."""
    worlds = cells.groupby("column", sort=False)["world"].nunique()
    shown = {
        (column, world): world_label(world)
        for column, world in zip(cells["column"], cells["world"], strict=True)
        if worlds[column] > 1
    }
    if len(set(shown.values())) < len(shown):
        shown = {key: key[1] for key in shown}
    return [
        f"{column} @ {shown[column, world]}" if (column, world) in shown else column
        for column, world in zip(cells["column"], cells["world"], strict=True)
    ]


def _column_headers(cells: pd.DataFrame, labels: Sequence[str]) -> dict[str, str]:
    """Each column of ``cells`` -> its header: named by the runs that hold it (``quick,
    again: a-a``, runs in the order of ``labels``) unless every run holds it; runs of other
    worlds cannot be told apart by their conditions' names."""
    holders = cells.groupby("column", sort=False)["run"].agg(set)
    return {
        column: column if len(runs) == len(labels) else
        f"{', '.join(r for r in labels if r in runs)}: {column}"
        for column, runs in holders.items()
    }  # fmt: skip


def _column_notes(headers: dict[str, str], labels: Sequence[str]) -> tuple[str, ...]:
    """A note where some columns name their runs and some (those in every run) do not."""
    plain = sum(header == column for column, header in headers.items())
    if plain in (0, len(headers)):
        return ()
    return (f"a column named by its condition alone is in every run ({', '.join(labels)})",)


def _row_labels(cells: pd.DataFrame) -> list[str]:
    """The row of each cell: its method label, or ``run: label`` where the label is ambiguous."""
    ambiguous = {
        method
        for method, rows in cells.groupby("method", sort=False)
        if rows["run"].nunique() > 1
        and (rows["config"].nunique() > 1 or rows["column"].duplicated().any())
    }
    return [
        f"{run}: {method}" if method in ambiguous else method
        for run, method in zip(cells["run"], cells["method"], strict=True)
    ]


def _settings_text(settings: BaseModel, fields: Sequence[str]) -> str:
    """``field value`` of each of ``fields`` of a settings model, comma-separated."""
    return ", ".join(f"{name} {getattr(settings, name)}" for name in fields)


def _check_same(
    runs: Sequence[RunData],
    names: Sequence[str],
    what: str,
    settings: Callable[[RunData], BaseModel],
    fields: Sequence[str],
) -> None:
    """DataError naming two runs whose ``settings`` (of ``what``, a metric) differ in ``fields``."""
    first = _settings_text(settings(runs[0]), fields)
    for name, run in zip(names, runs, strict=True):
        mine = _settings_text(settings(run), fields)
        if mine != first:
            raise DataError(
                f"leaderboard: {names[0]} and {name} define the {what} otherwise ({first}; "
                f"{mine}): their {what}s do not rank together; choose another --metric"
            )


def _checked_settings(runs: Sequence[RunData], names: Sequence[str], metric: str) -> AhcConfig:
    """The runs' AHC settings (the title names them), once the runs are known to compute
    ``metric`` alike: the AHC's definition and missing pairs for an AHC metric, every
    return-ratio setting for the RR; DataError naming two runs that differ."""
    if metric in AHC_METRICS:
        _check_same(runs, names, "AHC", lambda run: run.metrics.ahc, ("definition", "missing"))
    if metric == "rr":
        fields = tuple(ReturnRatioConfig.model_fields)
        _check_same(runs, names, "RR", lambda run: run.metrics.return_ratio, fields)
    return runs[0].metrics.ahc


def _text(value: float, source: str) -> str:
    """A summary value as its column shows it (scaled, rounded)."""
    _, digits, scale = SUMMARY_COLUMNS[source]
    return digits.text(value * scale)


def _cell_text(cell: dict[str, Any], metric: str, best: bool) -> str:
    """A cell of ``metric``: ``estimate [lo, hi]``, `` *`` when ``best``, then its companions
    where the method gave no estimate for some pair; ``--`` without an estimate."""
    if pd.isna(cell[metric]):
        return MISSING_TEXT
    low, high = (_text(cell[f"{metric}{end}"], metric) for end in ("_lo", "_hi"))
    shown = [f"{_text(cell[metric], metric)} [{low}, {high}]{BEST if best else ''}"]
    if cell["no_estimate_share"] > 0:
        shown += [_text(cell[c], c) for c in BOARD_METRICS[metric].companions]
    return COMPANION_SEPARATOR.join(shown)


def _title(metric: str, ahc: AhcConfig) -> str:
    """The board's title: what its cells show (AHC headers naming the runs' definition)."""
    header, *companions = (ahc_header(SUMMARY_COLUMNS[c][0], ahc)
                           for c in (metric, *BOARD_METRICS[metric].companions))  # fmt: skip
    listed = COMPANION_SEPARATOR.join(companions)
    then = f"; where a method gave no estimate for some pairs, then {listed}" if listed else ""
    return (
        f"{header} [95 % interval] per method and condition{then} ({BEST.strip()}: best "
        f"{header} in its column)"
    )


def leaderboard(
    run_dirs: Sequence[Path], labels: Sequence[str] = (), metric: str = "ahc"
) -> Leaderboard:
    """The ``metric`` (a key of :data:`BOARD_METRICS`) of every method of the grid runs in
    ``run_dirs`` under each condition, with its companions, the best of each column marked."""
    board = BOARD_METRICS[metric]
    names = run_labels(run_dirs, labels)
    runs = load_grid_runs(run_dirs)
    ahc = _checked_settings(runs, names, metric)
    columns = [metric, f"{metric}_lo", f"{metric}_hi", *board.companions, "no_estimate_share"]
    columns.append("n_goals")
    cells = _cells(runs, names, list(dict.fromkeys(columns)))
    headers = _column_headers(cells, names)
    cells["column"] = cells["column"].map(headers)
    cells["row"] = _row_labels(cells)
    _, digits, scale = SUMMARY_COLUMNS[metric]
    cells["shown"] = [digits.round(float(v) * scale) for v in cells[metric]]
    best = cells.groupby("column")["shown"].transform("max" if board.larger_better else "min")
    cells["text"] = [_cell_text(cell, metric, shown == top) for cell, shown, top in
                     zip(cells.to_dict("records"), cells["shown"], best, strict=True)]  # fmt: skip
    order = cells.sort_values("method", kind="stable")  # a label's rows together, runs in order
    rows, columns = list(dict.fromkeys(order["row"])), list(dict.fromkeys(cells["column"]))
    wide = cells.pivot(index="row", columns="column", values="text").reindex(rows)[columns]
    frame = wide.fillna(MISSING_TEXT).rename_axis(index="method", columns=None).reset_index()
    few = few_goals_note(cells["n_goals"])
    notes = (*_column_notes(headers, names), *([few] if few else []))
    view = make_view("leaderboard", _title(metric, ahc), frame, {}, notes=notes)
    return Leaderboard(view, names, [Path(d) for d in run_dirs], missing_results(runs, names))


def write_index(board: Leaderboard, path: Path) -> Path:
    """An HTML page at ``path``: the leaderboard, then each run with a link to its report
    (relative to the page), or a note when the run has none."""
    path = Path(path)
    items = []
    for label, run_dir in zip(board.labels, board.run_dirs, strict=True):
        report = next((run_dir / "report" / f for f in REPORT_FILES
                       if (run_dir / "report" / f).is_file()), None)  # fmt: skip
        if report is None:
            items.append(f"<li>{html.escape(label)}: no report</li>")
            continue
        link = html.escape(
            Path(os.path.relpath(report.resolve(), path.parent.resolve())).as_posix()
        )
        items.append(f'<li><a href="{link}">{html.escape(label)}</a></li>')
    table = board.view.text_frame().to_html(index=False, escape=True, border=0)
    notes = "".join(f"<p>{html.escape(note)}</p>\n" for note in board.view.notes)
    page = (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>homebench leaderboard'
        f"</title></head>\n<body>\n<h1>{html.escape(board.view.title)}</h1>\n{table}\n{notes}"
        f"<h2>Runs</h2>\n<ul>\n{chr(10).join(items)}\n</ul>\n</body></html>\n"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, page)
    return path
