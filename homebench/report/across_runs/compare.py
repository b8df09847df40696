"""``homebench compare``: how runs differ from the first, per cell, with intervals and tests.

The first run is the reference. For every cell (swept style, condition, method) that it
shares with another run, one row per metric: mean AE [deg], AHC and RR of the reference and of
the run, the change run - reference with its 95 % goal-bootstrap interval, the p-value and its
Holm adjustment over the whole table (the AE test is shared by the mean AE and AHC rows and
counts once), and the describe and home times, whose change is the ratio run / reference
(no test).

``test`` says how the cell was compared. **paired** when the runs share pairs, measured on the
same databases (:mod:`homebench.analysis.worlds`: the same grid position of another world is
another pair): their pairs
(return-ratio starts) are matched on goal and current (start) position, as
:mod:`homebench.analysis.comparisons` matches two methods, and the matched ones compared with
its paired goal bootstrap and sign-flip test; pairs of one run only (a missing job, a failed
pair, other goals) are left out, and a warning says so. **unpaired** when they share none: an
independent goal bootstrap of each run and a goal permutation test
(:mod:`homebench.analysis.unpaired`); a warning says when that is because their databases
differ. A method that gives no home direction has only its time ratios. A pair without an
estimate counts as 90 deg, as in the method comparisons, so a method that stops answering
shows; values are on the compared pairs and may differ from the summary's (mean AE over pairs
with an estimate). The AHC here is seed 001's (eq. 12, the cosine of the mean AE), whatever
definition the runs' tables use.
Every resample draws from a seed derived from the cell: the same runs give the same numbers.

``--fail-if`` thresholds (:class:`Threshold`) bound the change per cell.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from homebench.analysis.comparisons import (
    EMPTY_CELL,
    PAIR_POSITION,
    START_POSITION,
    Cell,
    compare_cells,
    holm_by_test,
    keyed_cells,
    matched,
)
from homebench.analysis.metrics import Missing, with_missing
from homebench.analysis.statistics import N_BOOT, Interval
from homebench.analysis.unpaired import unpaired_means
from homebench.analysis.worlds import world_keys, world_label
from homebench.errors import ConfigError
from homebench.fileio import write_text_atomic
from homebench.hashing import derived_seed
from homebench.report.across_runs.run_set import (
    load_grid_runs,
    missing_results,
    run_differences,
    run_labels,
)
from homebench.report.run_data import RunData
from homebench.report.tables import (
    FIXED0,
    FIXED2,
    FIXED3,
    Digits,
    TableView,
    make_view,
    to_csv,
    to_latex,
    to_markdown,
)

#: Compared metrics: summary column -> (header, digits, True when larger is better).
METRICS = {
    "mean_ae_deg": ("mean AE [deg]", FIXED2, False),
    "ahc": ("AHC", FIXED3, True),
    "rr": ("RR", FIXED3, True),
}
#: Times compared as ratios run / reference (summary columns).
TIMES = ("describe_ms", "home_ms")
#: How a pair without an estimate is compared (see compare_ae).
MISSING: Missing = "orthogonal"
COLUMNS = ["style", "condition", "method", "run", "metric", "reference", "value", "change",
           "lo", "hi", "n_goals_ref", "n_goals", "p", "p_holm", "test"]  # fmt: skip
#: A cell: (style, "" without a sweep; condition; method label).
CellKey = tuple[str, str, str]


@dataclass(frozen=True)
class Comparison:
    """``table``: numeric, ``COLUMNS`` (``style`` only when a run sweeps styles), one row per
    (cell, run, metric); ``differences``: config and environment lines (see
    :func:`~homebench.report.across_runs.run_set.run_differences`); ``warnings``: missing jobs, and
    cells
    absent from a run."""

    labels: list[str]
    table: pd.DataFrame
    differences: list[str]
    warnings: list[str]

    def differences_text(self) -> str:
        """The config and environment differences, a heading and a line each."""
        reference = self.labels[0]
        if not self.differences:
            return f"No differences from {reference} in config or environment."
        return "\n".join([f"Differences from {reference}:", *(f"  {d}" for d in self.differences)])

    def view(self) -> TableView:
        """The table rounded for printing and writing (CSV, MD, TeX)."""
        numbers = ("reference", "value", "change", "lo", "hi")
        digits = dict.fromkeys(numbers, FIXED3) | dict.fromkeys(("n_goals_ref", "n_goals"), FIXED0)
        digits |= dict.fromkeys(("p", "p_holm"), Digits(significant=2))
        title = (
            f"Runs compared with {self.labels[0]} (change = run - reference; "
            "times: run / reference)"
        )
        return make_view("comparison", title, self.table, digits)


@dataclass(frozen=True)
class _RunCells:
    """A run's AE cells (pairs), return-ratio cells (starts), times and world keys per
    cell."""

    ae: dict[CellKey, Cell]
    rr: dict[CellKey, Cell]
    times: dict[CellKey, dict[str, float]]
    worlds: dict[CellKey, str]


def _by_style(table: pd.DataFrame) -> Iterator[tuple[str, pd.DataFrame]]:
    if table.empty or "style" not in table.columns or table["style"].isna().all():
        yield "", table
        return
    yield from ((str(style), rows) for style, rows in table.groupby("style", sort=True))


def _run_cells(run: RunData) -> _RunCells:
    tables = run.tables
    ae, rr = {}, {}
    for style, rows in _by_style(tables.pairs):
        ae |= {(style, *k): v for k, v in keyed_cells(rows, PAIR_POSITION, "ae").items()}
    for style, rows in _by_style(tables.rr_starts):
        rr |= {(style, *k): v for k, v in keyed_cells(rows, START_POSITION, "success").items()}
    times = {}
    for record in tables.summary.to_dict("records"):
        style = record.get("style")
        key = ("" if pd.isna(style) else str(style), record["condition"], record["method"])
        times[key] = {t: float(record[t]) for t in TIMES}
    pairs = tables.pairs.assign(style=tables.pairs["style"].astype("object"))
    worlds = world_keys(pairs, ["style", "condition", "method"])
    return _RunCells(ae, rr, times, {key: str(worlds.get(key, "")) for key in times})


def compare_runs(
    run_dirs: Sequence[Path], labels: Sequence[str] = (), n_boot: int = N_BOOT
) -> Comparison:
    """Compare runs (at least two grid runs with results) with the first; DataError naming
    the folder that is not one. ``labels``: one per run (default: folder names)."""
    if len(run_dirs) < 2:
        raise ConfigError("compare needs at least two run folders")
    names = run_labels(run_dirs, labels)
    runs = load_grid_runs(run_dirs)
    warnings = missing_results(runs, names)
    cells = [_run_cells(run) for run in runs]
    rows = []
    for key in sorted(set().union(*(c.times for c in cells))):
        for name, found in zip(names, cells, strict=True):
            if key not in found.times:
                where = f" ({key[0]})" if key[0] else ""
                warnings.append(f"{name}: no results for {key[2]} under {key[1]}{where}")
        if key not in cells[0].times:
            continue
        for k, (name, found) in enumerate(zip(names[1:], cells[1:], strict=True)):
            if key not in found.times:
                continue
            cell = {"style": key[0], "condition": key[1], "method": key[2], "run": name}
            compared, (shared, n_reference, n_run) = _compare_cell(cells[0], found, key, n_boot)
            rows += [cell | row | {"test_id": f"{key}/{k}/{row['test_id']}"} for row in compared]
            where = f" ({key[0]})" if key[0] else ""
            worlds = cells[0].worlds[key], found.worlds[key]
            if worlds[0] != worlds[1]:
                warnings.append(
                    f"{name}: {key[2]} under {key[1]}{where}: other databases than "
                    f"{names[0]}'s ({world_label(worlds[1])}, not {world_label(worlds[0])}): "
                    "compared unpaired"
                )
            elif 0 < shared < max(n_reference, n_run):
                warnings.append(
                    f"{name}: {key[2]} under {key[1]}{where} compared on the {shared} pairs it "
                    f"shares with {names[0]} (of {n_run}; {n_reference} in {names[0]})"
                )
    table = pd.DataFrame(rows, columns=[*COLUMNS, "test_id"])
    table["p_holm"] = holm_by_test(table["p"], table["test_id"]) if len(table) else []
    swept = any(key[0] for c in cells for key in c.times)
    columns = COLUMNS if swept else COLUMNS[1:]
    return Comparison(names, table[columns], run_differences(runs, names), warnings)


def _compare_cell(
    reference: _RunCells, run: _RunCells, key: CellKey, n_boot: int
) -> tuple[list[dict[str, object]], tuple[int, int, int]]:
    """The rows of one cell of ``run`` against ``reference`` (the metrics, then the times),
    and how many pairs the two share, of how many in the reference and in the run: paired
    when they share pairs of the same databases; no metric for a method that gives no home
    direction (no AE cell in either run)."""
    seed = derived_seed("compare-runs", *key)
    ae = (reference.ae.get(key, EMPTY_CELL), run.ae.get(key, EMPTY_CELL))
    rr = (reference.rr.get(key, EMPTY_CELL), run.rr.get(key, EMPTY_CELL))
    shared = len(matched(*ae)[0]) if reference.worlds[key] == run.worlds[key] else 0
    paired = shared > 0
    directed = len(ae[0][1]) + len(ae[1][1]) > 0
    found: Found = {}
    if directed:
        found = _paired(ae, rr, seed, n_boot) if paired else _unpaired(ae, rr, seed, n_boot)
    test = "paired" if paired else "unpaired"
    rows = [
        {
            "metric": metric,
            "reference": ref.estimate,
            "value": mine.estimate,
            "change": change.estimate,
            "lo": change.lo,
            "hi": change.hi,
            "n_goals_ref": ref.n_goals,
            "n_goals": mine.n_goals,
            "p": p,
            "test": test,
            "test_id": "rr" if metric == "rr" else "ae",
        }  # fmt: skip
        for metric, (ref, mine, change, p) in found.items()
    ]
    for metric in TIMES:
        before, after = reference.times[key][metric], run.times[key][metric]
        ratio = after / before if before > 0 else math.nan
        rows.append({"metric": metric, "reference": before, "value": after, "change": ratio,
                     "test": "ratio", "test_id": metric})  # fmt: skip
    return rows, (shared, len(ae[0][1]), len(ae[1][1]))


#: Per metric: the reference's value, the run's, the change, and its p-value.
Found = dict[str, tuple[Interval, Interval, Interval, float]]


def _paired(ae: tuple[Cell, Cell], rr: tuple[Cell, Cell], seed: int, n_boot: int) -> Found:
    found_ae, found_rr = compare_cells(ae, rr, seed, MISSING, n_boot)
    degrees = [i.transformed(np.degrees) for i in (found_ae.mean_ae_a, found_ae.mean_ae_b,
                                                   found_ae.mean_ae)]  # fmt: skip
    return {
        "mean_ae_deg": (*degrees, found_ae.p_goal),
        "ahc": (found_ae.ahc_a, found_ae.ahc_b, found_ae.ahc, found_ae.p_goal),
        "rr": (found_rr.rr_a, found_rr.rr_b, found_rr.rr, found_rr.p_goal),
    }


def _unpaired(ae: tuple[Cell, Cell], rr: tuple[Cell, Cell], seed: int, n_boot: int) -> Found:
    """Unpaired: AE per pair; RR per start, which weighs every goal alike (each goal of a
    run has a start at every grid position), so it is the mean of the per-goal RR."""
    (keys_a, ae_a), (keys_b, ae_b) = ae
    on_ae = unpaired_means(with_missing(ae_a, MISSING), keys_a[:, :3],
                           with_missing(ae_b, MISSING), keys_b[:, :3], n_boot, seed)  # fmt: skip
    (starts_a, ok_a), (starts_b, ok_b) = rr
    on_rr = unpaired_means(ok_a, starts_a[:, :3], ok_b, starts_b[:, :3], n_boot, seed)
    ref_ae, run_ae = (r.interval() for r in (on_ae.a, on_ae.b))
    cos = ref_ae.transformed(np.cos, increasing=False), run_ae.transformed(np.cos, increasing=False)
    return {
        "mean_ae_deg": (
            ref_ae.transformed(np.degrees),
            run_ae.transformed(np.degrees),
            on_ae.difference(np.degrees),
            on_ae.p_value,
        ),  # fmt: skip
        "ahc": (*cos, on_ae.difference(np.cos), on_ae.p_value),
        "rr": (on_rr.a.interval(), on_rr.b.interval(), on_rr.difference(), on_rr.p_value),
    }


# --------------------------------------------------------------------------- thresholds

OPERATORS: dict[str, Callable[[float, float], bool]] = {
    "<=": operator.le,
    ">=": operator.ge,
    "<": operator.lt,
    ">": operator.gt,
}
_NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_THRESHOLD = re.compile(rf"\s*([A-Za-z_]+)\s*(<=|>=|<|>)\s*({_NUMBER})\s*")


@dataclass(frozen=True)
class Threshold:
    """``metric op limit`` on each run's change to the reference (a difference; for a time, a
    ratio), e.g. ``ahc < -0.02``: a cell whose change satisfies it is a regression."""

    metric: str
    op: str
    limit: float

    @classmethod
    def parse(cls, text: str) -> Threshold:
        """Read ``METRIC OP NUMBER`` (OP one of <, <=, >, >=); ConfigError otherwise."""
        found = _THRESHOLD.fullmatch(text)
        names = [*METRICS, *TIMES]
        if found is None or found[1] not in names:
            raise ConfigError(
                f"--fail-if {text!r}: expected METRIC OP NUMBER, e.g. 'ahc < -0.02' (METRIC: "
                f"{', '.join(names)}; OP: <, <=, >, >=)"
            )
        return cls(found[1], found[2], float(found[3]))

    def __str__(self) -> str:
        return f"{self.metric} {self.op} {self.limit:g}"

    def violations(self, table: pd.DataFrame) -> list[str]:
        """One line per row of a comparison ``table`` whose change meets the threshold (a
        NaN change meets none)."""
        rows = table[table["metric"] == self.metric]
        hit = [OPERATORS[self.op](float(c), self.limit) for c in rows["change"]]
        return [
            f"{row['run']}: {self.metric} change {row['change']:+.4g} under {row['condition']}"
            + (f" ({row['style']})" if row.get("style") else "")
            + f" for {row['method']} (--fail-if '{self}')"
            for row in rows[hit].to_dict("records")
        ]


# --------------------------------------------------------------------------- output file

RENDERERS: dict[str, Callable[[TableView], str]] = {
    ".csv": to_csv,
    ".md": to_markdown,
    ".tex": to_latex,
}


def renderer_for(path: Path) -> Callable[[TableView], str]:
    """How a table is written to ``path``, by its suffix; ConfigError for another suffix."""
    render = RENDERERS.get(Path(path).suffix.lower())
    if render is None:
        raise ConfigError(f"--out {path}: the file must end in .csv, .md or .tex")
    return render


def write_view_file(view: TableView, path: Path) -> Path:
    """Write ``view`` to ``path`` (atomically) in the format its suffix names."""
    render = renderer_for(path)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(Path(path), render(view))
    return Path(path)
