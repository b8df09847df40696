"""``homebench leaderboard``: one metric of several runs' methods, condition by condition.

Rows are method labels (in label order), columns conditions (``style/condition`` in a style
sweep) of one world: where runs hold a condition of the same name on other databases, each
world gets its own column, ``condition @ world`` (:mod:`homebench.analysis.worlds`). Each cell
is ``estimate [lo, hi]`` from its run's summary table (the 95 % goal-bootstrap interval), ``--``
where there is none (a method that gives no home direction has no direction metric). A method
label found in several runs becomes one row per run, ``run: label``, when its method or
parameters differ between them or when two of them hold it under the same column; otherwise
its runs' cells share one row. The best estimate of each column as shown (largest AHC or RR,
smallest mean AE; ties alike) is marked ``*``. The optional index page lists the table and
links each run's report.
"""

from __future__ import annotations

import html
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from pydantic import ValidationError

from homebench.analysis.worlds import world_keys, world_label
from homebench.config import MethodEntry
from homebench.fileio import write_text_atomic
from homebench.report.compare import METRICS
from homebench.report.run_data import CONFIG_FILE, RunData, validation_error
from homebench.report.run_set import load_grid_runs, run_labels
from homebench.report.tables import MISSING_TEXT, TableView, make_view

BEST = " *"
#: Report documents an index page links, most browsable first.
REPORT_FILES = ("report.html", "report.pdf", "report.md")


@dataclass(frozen=True)
class Leaderboard:
    """The table and the runs it was drawn from (labels and folders, in order)."""

    view: TableView
    labels: list[str]
    run_dirs: list[Path]


def method_configs(run: RunData) -> dict[str, str]:
    """Each method label of ``run``'s config (grid points included) -> its method name and
    parameters as canonical JSON; DataError naming the entry when one is invalid."""
    configs = {}
    for k, entry in enumerate(run.config.get("methods", [])):
        try:
            method = MethodEntry.model_validate(entry)
        except ValidationError as error:
            raise validation_error(run.run_dir / CONFIG_FILE, f"methods.{k}", error) from None
        for label, params in method.expand():
            configs[label] = json.dumps([method.method, params], sort_keys=True, default=str)
    return configs


def _cells(runs: Sequence[RunData], labels: Sequence[str], metric: str) -> pd.DataFrame:
    """One row per (run, summary row): run, method, column, the metric, lo, hi, config."""
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
                "estimate": row[metric],
                "lo": row[f"{metric}_lo"],
                "hi": row[f"{metric}_hi"],
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


def leaderboard(
    run_dirs: Sequence[Path], labels: Sequence[str] = (), metric: str = "ahc"
) -> Leaderboard:
    """The ``metric`` (``ahc``, ``rr`` or ``mean_ae_deg``) of every method of the grid runs
    in ``run_dirs`` under each condition, with the best of each column marked."""
    header, digits, larger_better = METRICS[metric]
    names = run_labels(run_dirs, labels)
    cells = _cells(load_grid_runs(run_dirs), names, metric)
    cells["row"] = _row_labels(cells)
    cells["shown"] = [digits.round(float(v)) for v in cells["estimate"]]
    best = cells.groupby("column")["shown"].transform("max" if larger_better else "min")
    cells["text"] = [
        MISSING_TEXT if pd.isna(e)
        else f"{digits.text(e)} [{digits.text(lo)}, {digits.text(hi)}]" + (BEST if s == b else "")
        for e, lo, hi, s, b in zip(cells["estimate"], cells["lo"], cells["hi"],
                                   cells["shown"], best, strict=True)
    ]  # fmt: skip
    order = cells.sort_values("method", kind="stable")  # a label's rows together, runs in order
    rows, columns = list(dict.fromkeys(order["row"])), list(dict.fromkeys(cells["column"]))
    wide = cells.pivot(index="row", columns="column", values="text").reindex(rows)[columns]
    frame = wide.fillna(MISSING_TEXT).rename_axis(index="method", columns=None).reset_index()
    title = f"{header} per method and condition, 95 % interval ({BEST.strip()}: best in its column)"
    view = make_view("leaderboard", title, frame, {})
    return Leaderboard(view, names, [Path(d) for d in run_dirs])


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
    page = (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>homebench leaderboard'
        f"</title></head>\n<body>\n<h1>{html.escape(board.view.title)}</h1>\n{table}\n"
        f"<h2>Runs</h2>\n<ul>\n{chr(10).join(items)}\n</ul>\n</body></html>\n"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, page)
    return path
