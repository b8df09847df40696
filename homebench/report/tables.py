"""Report tables: the run's metric tables with units in the headers, rounded, as CSV / MD / TeX
and as console text.

Views of a run's tables (``homebench.evaluation.results``): the headline (the summary's main
columns: AHC beside the AHC with a missing estimate as 90 deg and the share without an
estimate, so that a method that abstains does not rank above its homing; also printed by
``homebench run``), the metrics per distance band, the method x condition summary, the return
ratio per goal (seed 001, Figure 10 as a table, with each method's share of walks ended on a
position without an estimate), the AHC per distance bin (Figure 9 as a table)
and the paired comparisons of the methods. An AHC header names the run's AHC definition when it
is not the default (:func:`ahc_header`). Rows follow the run's config: conditions, then
methods, in the order the config lists them (:class:`RowOrder`).

Each view is a numeric frame rounded once, one precision rule (:class:`Digits`) per column.
A metric with a 95 % interval keeps its bounds as columns ``<header> lo`` and ``<header> hi``
of that frame (the CSV), and every other rendering shows it as one cell, ``estimate [lo, hi]``.
A view may mark cells (the summary: the method significantly best of its condition); Markdown
shows a marked cell in bold, LaTeX with ``\\bfseries``, the console with a trailing ``*``, the
PDF pages in bold, each with a note line saying what a mark means.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from homebench.analysis.tables import FLIP_DEG, RunTables
from homebench.config import AhcConfig, ReturnRatioConfig
from homebench.fileio import write_text_atomic
from homebench.report.run_data import RunData

if TYPE_CHECKING:
    from homebench.config import RunConfig

MISSING_TEXT = "--"
#: Significance level of a marked ("significantly best") cell, on Holm-adjusted goal-level
#: p-values.
ALPHA = 0.05
#: A LaTeX table with more rows is a ``longtable``, which splits across pages.
LATEX_PAGE_ROWS = 40
#: How the console marks a cell (bold elsewhere), and its width in characters.
CONSOLE_MARK = "*"
CONSOLE_WIDTH = 100


@dataclass(frozen=True)
class Digits:
    """How a column is rounded: ``decimals`` after the point, or ``significant`` digits;
    values below ``below`` print as "<below" (p-values)."""

    decimals: int | None = None
    significant: int | None = None
    below: float | None = None

    def _decimals_for(self, value: float) -> int:
        """Digits after the point to keep (negative: round to tens, hundreds, ...)."""
        if self.decimals is not None:
            return self.decimals
        if value == 0:
            return 0
        return (self.significant or 1) - 1 - math.floor(math.log10(abs(value)))

    def round(self, value: float) -> float:
        if math.isnan(value):
            return value
        return round(value, self._decimals_for(value)) + 0.0  # + 0.0: no "-0.00"

    def text(self, value: float) -> str:
        if math.isnan(value):
            return MISSING_TEXT
        if self.below is not None and value < self.below:
            return f"<{self.below:g}"
        rounded = self.round(value)
        return f"{rounded:.{max(0, self._decimals_for(rounded))}f}"


FIXED0, FIXED1, FIXED2, FIXED3 = Digits(0), Digits(1), Digits(2), Digits(3)
SIGNIFICANT3 = Digits(significant=3)
P_VALUE = Digits(significant=2, below=0.001)


@dataclass(frozen=True)
class TableView:
    """A table ready to print: ``frame`` (rounded, headers with units) and its column digits.

    Columns not in ``digits`` are text (conditions, methods, goals). ``bounds``: shown column
    -> its (lo, hi) columns of ``frame``, printed in the shown column's cell. ``marked``:
    (row, shown column) of the cells shown marked, ``mark_note`` what a mark means; ``notes``:
    further lines under the table. ``grouped``: the console and LaTeX show the swept world and
    condition as a heading over their rows instead of as columns (a narrower table).
    """

    name: str
    title: str
    frame: pd.DataFrame
    digits: dict[str, Digits]
    bounds: dict[str, tuple[str, str]] = field(default_factory=dict)
    marked: frozenset[tuple[int, str]] = frozenset()
    mark_note: str = ""
    notes: tuple[str, ...] = ()
    grouped: bool = False

    def group_columns(self) -> list[str]:
        """The columns shown as headings over their rows: none unless ``grouped``."""
        if not self.grouped:
            return []
        return [c for c in (*swept(self.frame), "condition") if c in self.frame.columns]

    def group_heads(self) -> list[str | None]:
        """Per row, the heading of the group it starts ("condition a-b"), else None."""
        columns = self.group_columns()
        keys = [", ".join(f"{c} {row[c]}" for c in columns) for _, row in self.frame.iterrows()]
        return [key if columns and (k == 0 or key != keys[k - 1]) else None
                for k, key in enumerate(keys)]  # fmt: skip

    def shown_columns(self) -> list[str]:
        """The columns the text renderings show: all but the bounds."""
        hidden = {c for pair in self.bounds.values() for c in pair}
        return [c for c in self.frame.columns if c not in hidden]

    def _text(self, column: str) -> list[str]:
        return [self.digits[column].text(v) for v in self.frame[column].astype(float)]

    def text_frame(self) -> pd.DataFrame:
        """Every shown cell as text: numbers rounded, ``estimate [lo, hi]`` where a column
        has bounds (the estimate alone where it has none, e.g. a single goal)."""
        shown = self.frame[self.shown_columns()].copy()
        for column in shown.columns.intersection(list(self.digits)):
            shown[column] = self._text(column)
        for column, (lo, hi) in self.bounds.items():
            shown[column] = [
                text if MISSING_TEXT in (text, low, high) else f"{text} [{low}, {high}]"
                for text, low, high in zip(shown[column], self._text(lo), self._text(hi),
                                           strict=True)
            ]  # fmt: skip
        return shown.astype(str)

    def mark_mask(self) -> np.ndarray:
        """Which cells of :meth:`text_frame` are marked, shape (rows, shown columns) bool."""
        columns = self.shown_columns()
        mask = np.zeros((len(self.frame), len(columns)), dtype=bool)
        for row, column in self.marked:
            mask[row, columns.index(column)] = True
        return mask

    def marked_frame(self, mark: Callable[[str], str], pad: str = "") -> pd.DataFrame:
        """:meth:`text_frame` with ``mark`` applied to the marked cells; the other cells of a
        column with a mark get ``pad`` (keeps the console's digits aligned)."""
        text, mask = self.text_frame(), self.mark_mask()
        for k, column in enumerate(text.columns):
            if mask[:, k].any():
                text[column] = [mark(v) if m else v + pad for v, m in zip(text[column], mask[:, k],
                                                                          strict=True)]  # fmt: skip
        return text

    def note_lines(self, mark: str) -> list[str]:
        """The lines under the table; ``mark`` names how marked cells look ("bold", "*")."""
        return [*([f"{mark}: {self.mark_note}"] if self.mark_note else []), *self.notes]

    def column_kinds(self) -> list[str]:
        """Per shown column: "text", "number" or "interval"."""
        return [
            "interval" if c in self.bounds else "number" if c in self.digits else "text"
            for c in self.shown_columns()
        ]

    def alignment(self) -> list[str]:
        return ["left" if kind == "text" else "right" for kind in self.column_kinds()]


def make_view(
    name: str,
    title: str,
    frame: pd.DataFrame,
    digits: dict[str, Digits],
    bounds: dict[str, tuple[str, str]] | None = None,
    marked: frozenset[tuple[int, str]] = frozenset(),
    mark_note: str = "",
    notes: tuple[str, ...] = (),
    grouped: bool = False,
) -> TableView:
    """A view of ``frame`` rounded by ``digits``; bound columns take their column's digits."""
    bounds = bounds or {}
    digits = {**digits, **{end: digits[c] for c, pair in bounds.items() for end in pair}}
    frame = frame.reset_index(drop=True)
    for column, rule in digits.items():
        rounded = pd.Series([rule.round(float(v)) for v in frame[column]], dtype=float)
        frame[column] = rounded.astype("Int64") if rule == FIXED0 else rounded
    return TableView(name, title, frame, digits, bounds, marked, mark_note, notes, grouped)


# --------------------------------------------------------------------------- row order


def _ranks(labels: Iterable[Any], listed: Sequence[str]) -> dict[str, int]:
    """The place of each of ``labels`` (as text): ``listed`` first, the others after, sorted."""
    extra = sorted({str(label) for label in labels} - set(listed))
    return {label: k for k, label in enumerate([*listed, *extra])}


@dataclass(frozen=True)
class RowOrder:
    """The order of a table's conditions and methods: as the run's config lists them; labels
    it does not list come last, sorted."""

    conditions: tuple[str, ...] = ()
    methods: tuple[str, ...] = ()

    def method_ranks(self, labels: Iterable[Any]) -> dict[str, int]:
        """The place of each method label of ``labels`` in this order."""
        return _ranks(labels, self.methods)

    def methods_of(self, labels: Iterable[Any]) -> list[str]:
        """``labels`` (method labels, repeats allowed) once each, in this order."""
        ranks = self.method_ranks(labels)
        return sorted(ranks.keys() & {str(label) for label in labels}, key=ranks.__getitem__)

    def sort(self, frame: pd.DataFrame, then: Sequence[str] = ()) -> pd.DataFrame:
        """``frame``'s rows by swept world (style, seed), condition and method in this order,
        then by its columns ``then``; stable, index reset."""
        keys = frame[swept(frame)].copy()
        for column, listed in (("condition", self.conditions), ("method", self.methods)):
            if column in frame.columns:
                keys[column] = frame[column].astype(str).map(_ranks(frame[column], listed))
        keys[list(then)] = frame[list(then)]
        if keys.columns.empty:
            return frame.reset_index(drop=True)
        ordered = keys.sort_values(list(keys.columns), kind="stable", na_position="first").index
        return frame.loc[ordered].reset_index(drop=True)


def run_order(run: RunData) -> RowOrder:
    """The config order of a run folder's conditions and methods (``config["methods"]``: the
    method entries of the resolved config, each expanded to its grid points' labels)."""
    labels = [label for label, _, _ in run.settings.method_points()]
    return RowOrder(tuple(run.conditions), tuple(labels))


def config_order(config: RunConfig) -> RowOrder:
    """The order of a validated run config's conditions and methods."""
    return RowOrder(
        tuple(condition for condition, _, _ in config.condition_pairs()),
        tuple(label for label, _, _ in config.method_points()),
    )


# --------------------------------------------------------------------------- views


#: Summary columns: source column -> (header, digits, scale). A source with ``_lo`` and
#: ``_hi`` columns in the summary is shown with its interval.
SUMMARY_COLUMNS = {
    "n_goals": ("n goals", FIXED0, 1.0),
    "pairs": ("pairs", FIXED0, 1.0),
    "no_estimate_share": ("no estimate [%]", FIXED1, 100.0),
    "mean_ae_deg": ("mean AE [deg]", FIXED2, 1.0),
    "median_ae_deg": ("median AE [deg]", FIXED2, 1.0),
    "rotation_error_deg": ("rotation error [deg]", FIXED2, 1.0),
    "rotation_flip_share": ("rotation flips [%]", FIXED1, 100.0),
    "ahc": ("AHC", FIXED3, 1.0),
    "ahc_missing90": ("AHC (no estimate = 90 deg)", FIXED3, 1.0),
    "rr": ("RR", FIXED3, 1.0),
    "catchment": ("catchment", FIXED3, 1.0),
    "describe_ms": ("describe [ms/image]", SIGNIFICANT3, 1.0),
    "home_ms": ("home [ms/pair]", SIGNIFICANT3, 1.0),
}
#: Columns left out of a view when no row has a value (no method of the run reports
#: rotations).
OPTIONAL = ("rotation_error_deg", "rotation_flip_share")
#: Summary columns marked where a method is significantly best: source column -> (metric of
#: :func:`~homebench.analysis.comparisons.comparison_table`, whether lower is better).
MARKED = {
    "mean_ae_deg": ("mean_ae_deg", True),
    "ahc": ("ahc", False),
    "ahc_missing90": ("ahc", False),
    "rr": ("rr", False),
}
#: The compared metrics, in the order of the comparisons table.
COMPARED = ("mean_ae_deg", "ahc", "rr")
INTERVAL_NOTE = (
    "[lo, hi]: 95 % interval of a bootstrap over goals (none with a single goal)."
)  # fmt: skip
#: Intervals from fewer goals than this get a visible note (:func:`few_goals_note`).
FEW_GOALS = 5


def few_goals_note(n_goals: Iterable[float]) -> str:
    """The note under a table or in a caption whose intervals rest on ``n_goals`` goals each
    (one count per interval; NaN and single goals, which have no interval, ignored): "" when
    every interval rests on FEW_GOALS goals or more."""
    counts = [int(n) for n in n_goals if not pd.isna(n) and n >= 2]
    few = sorted({n for n in counts if n < FEW_GOALS})
    if not few:
        return ""
    which = "The" if len(few) == len(set(counts)) else "Some"
    rest = f"{few[0]}" if len(few) == 1 else f"{few[0]} to {few[-1]}"
    return (
        f"{which} intervals here rest on {rest} goals, fewer than {FEW_GOALS}: a bootstrap over "
        "so few goals cannot reach beyond their values (with 3 goals it covers about 75 % "
        "whatever its level), so read them as rough ranges."
    )


SIGNIFICANCE_NOTE = (
    f"the best value of its condition, and better than every other method of the condition "
    f"in a goal-level sign-flip test (p < {ALPHA:g}, Holm-adjusted across the run's "
    f"comparisons, within each style; AE and AHC compared with a missing estimate as 90 deg)."
)

#: The AHC definition of a run that names none, how a header names a definition when a run
#: uses another one (:func:`ahc_header`), and what each definition is.
DEFAULT_AHC = AhcConfig()
AHC_TAGS = {"cos_mean_ae": "eq. 12", "mean_cos": "mean cos"}
AHC_MEANINGS = {
    "cos_mean_ae": "the cosine of the mean AE (seed 001, eq. 12)",
    "mean_cos": "the mean of cos(AE) (as Vardy & Moeller report it)",
}
#: The RR settings of a run that names none, and how each reading of
#: ``metrics.return_ratio.no_estimate`` treats a walk that ends on a position without an
#: estimate (:data:`homebench.config.RRNoEstimate`).
DEFAULT_RR = ReturnRatioConfig()
RR_NO_ESTIMATE_MEANINGS = {
    "fail": "as a failure (metrics.return_ratio.no_estimate: fail, the default: seed 001's "
    "step procedure is silent on abstentions)",
    "arrived": "as an arrival when that position is one of the goal's 8 grid neighbours, a "
    "failure elsewhere (metrics.return_ratio.no_estimate: arrived)",
}


def rr_reading(rr: ReturnRatioConfig = DEFAULT_RR) -> str:
    """The run's RR settings in words, every length with its unit (grid units): "steps of 0.8
    grid units (multiples of the grid spacing), success radius 0.5 grid units, ..."."""
    travel = (
        "half the grid's perimeter" if rr.max_travel is None else f"{rr.max_travel:g} grid units"
    )
    return (
        f"steps of {rr.rh:g} grid units (multiples of the grid spacing), success radius "
        f"{rr.success_radius:g} grid units, max travel {travel}; a walk that ends on a position "
        f"without an estimate counts {RR_NO_ESTIMATE_MEANINGS[rr.no_estimate]}"
    )


#: The header of the AHC with a missing estimate as 90 deg in the console, where the
#: headline's is too wide.
SHORT_AHC90 = "AHC90"


def ahc_header(header: str, ahc: AhcConfig = DEFAULT_AHC) -> str:
    """``header`` naming the run's AHC definition when it is not the default one: "AHC" ->
    "AHC (mean cos)", "AHC (no est. = 90 deg)" -> "AHC (mean cos; no est. = 90 deg)"; every
    other header as it is."""
    if ahc.definition == DEFAULT_AHC.definition or not re.fullmatch(r"AHC( \(.*\))?", header):
        return header
    tag = AHC_TAGS[ahc.definition]
    return f"AHC ({tag})" if header == "AHC" else f"AHC ({tag}; {header[len('AHC (') :]}"


#: What each metric column of a view is (after its header; see :func:`metrics_note`).
MEANINGS = {
    "no_estimate_share": "the pairs for which the method gave no estimate",
    "mean_ae_deg": "over the pairs with an estimate",
    "rotation_flip_share": f"rotation estimates off by more than {FLIP_DEG:g} deg",
    "ahc_missing90": "the same with a missing estimate counted as 90 deg, so that a method "
    "gains nothing by abstaining",
    "rr": "over the goals whose home field covers the grid (n/a on posed images, no grid)",
}


def metrics_note(
    headers: dict[str, str], ahc: AhcConfig = DEFAULT_AHC, rr: ReturnRatioConfig = DEFAULT_RR
) -> str:
    """What the metric columns of a view are, in its order: ``headers``, source -> header of
    the columns it shows; ``ahc``, the run's AHC settings; ``rr``, its RR settings (their
    reading of an abstention said when it is not the default)."""
    kept = (
        "over the pairs with an estimate (the paper's reading)"
        if ahc.missing == "exclude"
        else "with a missing estimate as 90 deg (metrics.ahc.missing)"
    )
    meanings = {**MEANINGS, "ahc": f"{AHC_MEANINGS[ahc.definition]}, {kept}"}
    if rr.no_estimate != DEFAULT_RR.no_estimate:
        meanings["rr"] = (
            f"{MEANINGS['rr']}; a walk that ends on a position without an estimate counts "
            f"{RR_NO_ESTIMATE_MEANINGS[rr.no_estimate]}"
        )
    said = [f"{header}: {meanings[source]}" for source, header in headers.items()
            if source in meanings]  # fmt: skip
    missing = "--: no value (a method that gives no home direction has no AE, AHC or RR)."
    return "; ".join([*said, missing])


#: The headline table's columns: summary source -> header (digits and scale as in
#: SUMMARY_COLUMNS), and those shown with their interval; the console's, narrower.
HEADLINE_COLUMNS = {
    "ahc": "AHC",
    "ahc_missing90": "AHC (no est. = 90 deg)",
    "no_estimate_share": "no est. [%]",
    "rr": "RR",
    "mean_ae_deg": "mean AE [deg]",
    "rotation_error_deg": "rotation error [deg]",
    "rotation_flip_share": "rotation flips [%]",
    "home_ms": "home [ms]",
}
HEADLINE_INTERVALS = ("ahc", "rr")
CONSOLE_COLUMNS = {
    source: SHORT_AHC90 if source == "ahc_missing90" else header
    for source, header in HEADLINE_COLUMNS.items()
    if not source.startswith("rotation")
}
CONSOLE_INTERVALS = ("ahc",)
HEADLINE_NOTE = (
    "home: ms per pair. Every column with its interval (pairs, median AE, rotation error and "
    "flips, catchment, describe time): the summary table in tables/ (csv, md, tex); per "
    "distance band: the band table."
)
#: The band table's columns: band table source -> header (digits and scale as in
#: SUMMARY_COLUMNS), and those shown with their interval.
BAND_COLUMNS = {
    "pairs": "pairs",
    "ahc": "AHC",
    "ahc_missing90": "AHC (no est. = 90 deg)",
    "no_estimate_share": "no est. [%]",
    "mean_ae_deg": "mean AE [deg]",
    "rotation_error_deg": "rotation error [deg]",
    "rotation_flip_share": "rotation flips [%]",
}
BAND_INTERVALS = ("ahc", "no_estimate_share", "mean_ae_deg")


def _few_goals(table: pd.DataFrame) -> tuple[str, ...]:
    """:func:`few_goals_note` of a table's ``n_goals`` column, as a tuple of notes (none when
    it needs no note or has no such column)."""
    note = few_goals_note(table["n_goals"]) if "n_goals" in table.columns else ""
    return (note,) if note else ()


def swept(table: pd.DataFrame) -> list[str]:
    """The world factors a table varies over ("style", "seed"), for its row labels."""
    return [c for c in ("style", "seed") if c in table.columns and table[c].notna().any()]


def _bounded(
    frame: pd.DataFrame, header: str, values: pd.DataFrame, source: str, scale: float = 1.0
) -> tuple[str, str] | None:
    """Add ``values[source]`` (times ``scale``) to ``frame`` as ``header``, with its bounds as
    ``header lo`` and ``header hi`` when ``values`` has them; the bound columns' names."""
    frame[header] = values[source].astype(float).to_numpy() * scale
    if f"{source}_lo" not in values.columns:
        return None
    ends = (f"{header} lo", f"{header} hi")
    for end, name in zip(("_lo", "_hi"), ends, strict=True):
        frame[name] = values[f"{source}{end}"].astype(float).to_numpy() * scale
    return ends


class _Comparisons:
    """The comparison rows of a run (``method_comparisons``), looked up by cell and methods."""

    def __init__(self, comparisons: pd.DataFrame, factors: list[str]) -> None:
        self.factors = factors
        self.rows = {
            (*(row[f] for f in factors), row["metric"], frozenset((row["method_a"],
                                                                   row["method_b"]))): row
            for row in comparisons.to_dict("records")
        }  # fmt: skip

    def beats(self, cell: tuple[Any, ...], metric: str, lower: bool, a: str, b: str) -> bool:
        """Whether ``a`` is significantly better than ``b`` on ``metric`` in ``cell``."""
        row = self.rows.get((*cell, metric, frozenset((a, b))))
        if row is None or not row["p_goal_holm"] < ALPHA:
            return False
        mine, theirs = (
            (row["value_a"], row["value_b"]) if row["method_a"] == a else
            (row["value_b"], row["value_a"])
        )  # fmt: skip
        return bool(mine < theirs if lower else mine > theirs)


def significant_cells(
    summary: pd.DataFrame, comparisons: pd.DataFrame
) -> frozenset[tuple[int, str]]:
    """(row, source column) of ``summary`` (one row per swept style, condition and method)
    where the method is significantly best of its condition: best value of the column and,
    in every comparison with another method of the condition, better at p_goal_holm < ALPHA.
    """
    factors = [*swept(summary), "condition"]
    found = _Comparisons(comparisons, factors)
    cells = set()
    marked = {c: rule for c, rule in MARKED.items() if c in summary.columns}
    for cell, rows in summary.groupby(factors, sort=False, dropna=False):
        for column, (metric, lower) in marked.items():
            values = rows[column].astype(float)
            if values.notna().sum() < 2:
                continue
            best = values.idxmin() if lower else values.idxmax()
            mine = rows.at[best, "method"]
            others = rows.loc[values.notna() & (rows.index != best), "method"]  # n/a: unranked
            if all(found.beats(cell, metric, lower, mine, other) for other in others):
                cells.add((int(best), column))
    return frozenset(cells)


@dataclass(frozen=True)
class _MetricColumns:
    """A table's factors and metric columns as :func:`make_view` takes them, and ``shown``:
    source -> header of each metric column shown."""

    frame: pd.DataFrame
    digits: dict[str, Digits]
    bounds: dict[str, tuple[str, str]]
    shown: dict[str, str]


def _metric_columns(
    table: pd.DataFrame,
    factors: list[str],
    headers: dict[str, str],
    intervals: Collection[str] | None,
    ahc: AhcConfig,
) -> _MetricColumns:
    """``table``'s ``factors``, then its columns ``headers`` (source -> header, AHC headers
    naming the run's definition, ``ahc``; digits and scale of SUMMARY_COLUMNS; a source it
    lacks, or an OPTIONAL one without a value, left out), those in ``intervals`` (None: every
    one that has bounds) with their bounds."""
    frame = table[factors].copy()
    digits, bounds, shown = {}, {}, {}
    for source, header in headers.items():
        if source not in table.columns or (source in OPTIONAL and table[source].isna().all()):
            continue
        _, rule, scale = SUMMARY_COLUMNS[source]
        shown[source] = ahc_header(header, ahc)
        digits[shown[source]] = rule
        values = table if intervals is None or source in intervals else table[[source]]
        ends = _bounded(frame, shown[source], values, source, scale)
        bounds |= {shown[source]: ends} if ends else {}
    return _MetricColumns(frame, digits, bounds, shown)


def _summary_columns(
    name: str,
    title: str,
    summary: pd.DataFrame,
    order: RowOrder,
    comparisons: pd.DataFrame,
    headers: dict[str, str],
    intervals: Collection[str] | None,
    ahc: AhcConfig,
    notes: tuple[str, ...] = (),
    grouped: bool = False,
    rr: ReturnRatioConfig = DEFAULT_RR,
) -> TableView:
    """A view of the summary's rows in ``order`` (swept world, condition, method) and its
    columns ``headers`` (:func:`_metric_columns`), significantly best cells (``comparisons``:
    the run's method comparisons) marked; the interval and metric notes, then ``notes``."""
    summary = order.sort(summary)
    factors = [*swept(summary), "condition", "method"]
    columns = _metric_columns(summary, factors, headers, intervals, ahc)
    marked = {(row, columns.shown[column])
              for row, column in significant_cells(summary, comparisons)
              if column in columns.shown}  # fmt: skip
    few = few_goals_note(summary["n_goals"]) if "n_goals" in summary else ""
    notes = (INTERVAL_NOTE, *([few] if few else []), metrics_note(columns.shown, ahc, rr), *notes)
    return make_view(name, title, columns.frame, columns.digits, columns.bounds,
                     frozenset(marked), SIGNIFICANCE_NOTE, notes, grouped)  # fmt: skip


def summary_view(
    summary: pd.DataFrame,
    order: RowOrder,
    comparisons: pd.DataFrame,
    ahc: AhcConfig = DEFAULT_AHC,
    timing_note: str = "",
    rr: ReturnRatioConfig = DEFAULT_RR,
) -> TableView:
    """Method x condition summary (per swept style) in ``order``: goals, pairs, share without
    estimate, AE, rotation error and flips, AHC (the paper's and with a missing estimate as
    90 deg; ``ahc``: the run's AHC settings), RR, catchment, times (``timing_note``, the
    host's load while they were measured, under the table); each metric with its interval;
    significantly best cells (``comparisons``: the run's
    :func:`~homebench.analysis.tables.method_comparisons`) marked."""
    headers = {source: header for source, (header, _, _) in SUMMARY_COLUMNS.items()}
    title = "Summary per condition and method: estimate [95 % interval]"
    notes = (timing_note,) if timing_note else ()
    return _summary_columns("summary", title, summary, order, comparisons, headers, None, ahc,
                            notes, rr=rr)  # fmt: skip


def headline_view(
    summary: pd.DataFrame,
    order: RowOrder,
    comparisons: pd.DataFrame,
    ahc: AhcConfig = DEFAULT_AHC,
    console: bool = False,
    timing_note: str = "",
    rr: ReturnRatioConfig = DEFAULT_RR,
) -> TableView:
    """The summary's HEADLINE_COLUMNS (AHC, AHC with a missing estimate as 90 deg and the
    share without estimate beside it, RR, mean AE, rotation error and flips, home time),
    HEADLINE_INTERVALS with their interval, marks as in :func:`summary_view`: the report's
    first table; ``console``: the narrower CONSOLE_COLUMNS, CONSOLE_INTERVALS alone with their
    interval (the summary ``homebench run`` prints); ``timing_note``: the host's load while
    the times were measured, under the table; ``rr``: the run's RR settings."""
    title = "Results per condition and method: estimate [95 % interval]"
    headers, intervals = (
        (CONSOLE_COLUMNS, CONSOLE_INTERVALS) if console else (HEADLINE_COLUMNS, HEADLINE_INTERVALS)
    )
    notes = (HEADLINE_NOTE, *((timing_note,) if timing_note else ()))
    return _summary_columns("headline", title, summary, order, comparisons, headers, intervals,
                            ahc, notes, grouped=True, rr=rr)  # fmt: skip


def band_view(bands: pd.DataFrame, order: RowOrder, ahc: AhcConfig = DEFAULT_AHC) -> TableView:
    """The metrics per distance band (:func:`~homebench.analysis.tables.band_table`) of each
    condition and method in ``order``, the nearest band first, bands without a pair left out:
    BAND_COLUMNS (AHC headers naming the run's definition, ``ahc``), BAND_INTERVALS with their
    interval."""
    held = bands[bands["pairs"] > 0].rename(columns={"band": "distance"})
    bands = order.sort(held, then=["low_m"])
    factors = [*swept(bands), "condition", "method", "distance"]
    columns = _metric_columns(bands, factors, BAND_COLUMNS, BAND_INTERVALS, ahc)
    title = (
        "Results per band of distance between current and goal position: estimate [95 % interval]"
    )
    notes = (
        INTERVAL_NOTE,
        *_few_goals(bands),
        metrics_note(columns.shown, ahc),
        "Each band's metrics are over its own pairs, so a method that homes well near the "
        "goal and fails far from it is not hidden in one mean over every distance.",
    )
    return make_view("bands", title, columns.frame, columns.digits, columns.bounds,
                     notes=notes, grouped=True)  # fmt: skip


def _pivot(
    table: pd.DataFrame, index: list[str], value: str, order: RowOrder
) -> tuple[pd.DataFrame, list[str]]:
    """``table`` wide: one row per ``index`` value (conditions in ``order``), one column per
    method (in ``order``)."""
    wide = table.pivot(index=index, columns="method", values=value).sort_index()
    methods = order.methods_of(wide.columns)
    wide.columns = [str(c) for c in wide.columns]
    return order.sort(wide[methods].reset_index()), methods


#: The rr_by_goal column of a method's share of RR walks ended on a position without an
#: estimate.
RR_ENDED = "{} ended on no est. [%]"


def rr_by_goal_view(
    goals: pd.DataFrame, order: RowOrder, rr: ReturnRatioConfig = DEFAULT_RR
) -> TableView:
    """Return ratio per condition and goal, one column per method (Figure 10 as a table),
    then per method the share of the goal's RR walks that ended on a position without an
    estimate (RR_ENDED; ``rr_no_estimate_share`` of the goal table, in %; absent from goal
    tables written before it, then NaN); the notes say the run's RR settings (``rr``)."""
    factors = swept(goals)
    index = [*factors, "condition", "goal_i", "goal_j"]
    wide, methods = _pivot(goals, index, "rr", order)
    if "rr_no_estimate_share" not in goals.columns:
        goals = goals.assign(rr_no_estimate_share=math.nan)
    ended = _pivot(goals, index, "rr_no_estimate_share", order)[0][methods] * 100.0
    ended.columns = [RR_ENDED.format(m) for m in methods]
    goal = [f"({i}, {j})" for i, j in zip(wide["goal_i"], wide["goal_j"], strict=True)]
    frame = pd.concat([wide[[*factors, "condition"]], pd.Series(goal, name="goal (i, j)"),
                       wide[methods], ended], axis=1)  # fmt: skip
    title = "Return ratio per goal (share of start positions that reach the goal)"
    notes = (
        f"RR: {rr_reading(rr)}.",
        f"{RR_ENDED.format('<method>')}: the goal's RR walks that ended on a position without "
        "an estimate.",
    )
    digits = {**dict.fromkeys(methods, FIXED3), **dict.fromkeys(ended.columns, FIXED1)}
    return make_view("rr_by_goal", title, frame, digits, notes=notes)


def ahc_by_distance_view(
    table: pd.DataFrame, order: RowOrder, ahc: AhcConfig = DEFAULT_AHC
) -> TableView:
    """AHC per distance bin with its interval, one column per method (Figure 9 as a table;
    ``table``: the run's AHC table, ``ahc``: its settings).

    The "all" row (in the summary) and bins without any pair are left out.
    """
    binned = table[(table["bin"] != "all") & (table["n"] > 0)]
    index = [*swept(binned), "condition", "centre_cm"]
    wide, methods = _pivot(binned, index, "ahc", order)
    frame = wide.rename(columns={"centre_cm": "distance [cm]"})
    bounds = {}
    for method in methods:
        ends = (f"{method} lo", f"{method} hi")
        for end, name in zip(("ahc_lo", "ahc_hi"), ends, strict=True):
            frame[name] = _pivot(binned, index, end, order)[0][method]
        bounds[method] = ends
    digits = {"distance [cm]": FIXED0, **dict.fromkeys(methods, FIXED3)}
    name = ahc_header("AHC", ahc)
    title = (
        f"{name} by distance between current and goal position (bin centres): "
        f"{name} [95 % interval]"
    )
    notes = (INTERVAL_NOTE, *_few_goals(binned))
    return make_view("ahc_by_distance", title, frame, digits, bounds, notes=notes)


def _oriented(comparisons: pd.DataFrame, order: RowOrder) -> pd.DataFrame:
    """``comparisons`` with A the method listed first in ``order`` (B - A and its interval
    negated where A and B swap; the two-sided p-values stay)."""
    ranks = order.method_ranks([*comparisons["method_a"], *comparisons["method_b"]])
    swap = (comparisons["method_a"].map(ranks) > comparisons["method_b"].map(ranks)).to_numpy()
    out = comparisons.copy()
    for a, b in (("method_a", "method_b"), ("value_a", "value_b"), ("lo", "hi")):
        out.loc[swap, [a, b]] = comparisons.loc[swap, [b, a]].to_numpy()
    for column in ("difference", "lo", "hi"):
        out.loc[swap, column] = -out.loc[swap, column]
    return out


def comparisons_view(
    comparisons: pd.DataFrame, order: RowOrder, ahc: AhcConfig = DEFAULT_AHC
) -> TableView:
    """The paired comparisons of the methods per condition (``comparisons``: the run's
    :func:`~homebench.analysis.tables.method_comparisons`), in ``order``: B - A with its
    interval and both Holm-adjusted p-values; the AHC named by its definition (``ahc``)."""
    oriented = _oriented(comparisons, order)
    ranks = order.method_ranks([*oriented["method_a"], *oriented["method_b"]])
    oriented = order.sort(
        oriented.assign(
            metric_rank=oriented["metric"].map({m: k for k, m in enumerate(COMPARED)}),
            a_rank=oriented["method_a"].map(ranks),
            b_rank=oriented["method_b"].map(ranks),
        ),
        then=["metric_rank", "a_rank", "b_rank"],
    )
    frame = oriented[[*swept(oriented), "condition"]].copy()
    frame["metric"] = [ahc_header(SUMMARY_COLUMNS[m][0], ahc) for m in oriented["metric"]]
    frame["A"], frame["B"] = oriented["method_a"], oriented["method_b"]
    renamed = oriented.rename(columns={"lo": "difference_lo", "hi": "difference_hi"})
    ends = _bounded(frame, "B - A", renamed, "difference")
    frame["p goal (Holm)"] = oriented["p_goal_holm"].astype(float)
    frame["p pair test (Holm)"] = oriented["p_pair_holm"].astype(float)
    frame["n goals"] = oriented["n_goals"]
    digits = {"B - A": FIXED3, "p goal (Holm)": P_VALUE, "p pair test (Holm)": P_VALUE,
              "n goals": FIXED0}  # fmt: skip
    title = "Methods compared per condition on the same pairs: B - A [95 % interval]"
    notes = (
        "B - A: paired bootstrap over goals; AE and AHC on every pair both methods were "
        "given, a missing estimate counted as 90 deg; RR on the starts both share.",
        "p goal (Holm): sign-flip test over goals; p pair test (Holm): Wilcoxon signed-rank "
        "over pairs (AE, AHC) or McNemar over starts (RR), which ignore that pairs cluster by "
        "goal; Holm-adjusted across the run's comparisons (within each style).",
        *_few_goals(oriented),
    )
    bounds = {"B - A": ends} if ends else {}
    return make_view("comparisons", title, frame, digits, bounds, notes=notes)


def report_views(tables: RunTables, order: RowOrder, timing_note: str = "") -> list[TableView]:
    """The report tables of a run in ``order``, the headline first, then the distance bands
    (none when the run has no results; no comparisons with a single method, no bands in
    tables made without them); ``timing_note`` (the host's load while the times were
    measured) under the tables with timing columns, the headline and the summary."""
    if tables.pairs.empty:
        return []
    comparisons, ahc, rr = tables.comparisons, tables.metrics.ahc, tables.metrics.return_ratio
    views = [
        headline_view(tables.summary, order, comparisons, ahc, timing_note=timing_note, rr=rr),
        *([band_view(tables.bands, order, ahc)] if len(tables.bands) else []),
        summary_view(tables.summary, order, comparisons, ahc, timing_note, rr),
        rr_by_goal_view(tables.goals, order, rr),
        ahc_by_distance_view(tables.ahc, order, ahc),
    ]
    return views + ([comparisons_view(comparisons, order, ahc)] if len(comparisons) else [])


# --------------------------------------------------------------------------- writers


def to_markdown(view: TableView) -> str:
    text = view.marked_frame(lambda cell: f"**{cell}**").to_markdown(
        index=False, disable_numparse=True, colalign=view.alignment()
    )
    notes = "".join(f"\n{line}\n" for line in view.note_lines("**bold**"))
    return f"**{view.title}**\n\n{text}\n{notes}"


def to_text(view: TableView, width: int = CONSOLE_WIDTH) -> str:
    """The console table: title, cells (marked ones with CONSOLE_MARK), note lines wrapped to
    ``width``; a grouped view's group headings on lines of their own over their (indented)
    rows."""
    cells = view.marked_frame(lambda cell: cell + CONSOLE_MARK, pad=" ")
    groups = view.group_columns()
    shown = [c for c in cells.columns if c not in groups]
    align = [a for c, a in zip(cells.columns, view.alignment(), strict=True) if c in shown]
    lines = _columns([[c, *cells[c]] for c in shown], align)
    indent = "  " if groups else ""
    body = [indent + line for line in lines[:2]]
    for head, line in zip(view.group_heads(), lines[2:], strict=True):
        body += [head] if head is not None else []
        body.append(indent + line)
    title, notes = _wrapped([view.title], width), _wrapped(view.note_lines(CONSOLE_MARK), width)
    return "\n".join([*title, *body, *notes])


def console_summary(
    summary: pd.DataFrame,
    order: RowOrder,
    comparisons: pd.DataFrame,
    ahc: AhcConfig = DEFAULT_AHC,
    rr: ReturnRatioConfig = DEFAULT_RR,
) -> str:
    """The summary ``homebench run`` prints: the headline table's console view (AHC, AHC with
    a missing estimate as 90 deg, share without estimate, RR, mean AE, home time; ``ahc``,
    ``rr``: the run's AHC and RR settings), within CONSOLE_WIDTH columns for the usual
    condition and method names."""
    return to_text(headline_view(summary, order, comparisons, ahc, console=True, rr=rr))


def _columns(columns: list[list[str]], alignment: list[str]) -> list[str]:
    """Text ``columns`` (each its header, then its cells) side by side, two spaces apart, each
    as wide as its widest cell and aligned "left" or "right": the header, a rule, the rows."""
    widths = [max(len(cell) for cell in column) for column in columns]
    lines = [
        "  ".join(cell.ljust(w) if a == "left" else cell.rjust(w)
                  for cell, w, a in zip(row, widths, alignment, strict=True)).rstrip()
        for row in zip(*columns, strict=True)
    ]  # fmt: skip
    return [lines[0], "  ".join("-" * w for w in widths), *lines[1:]]


def _wrapped(lines: list[str], width: int) -> list[str]:
    """``lines`` wrapped to ``width`` characters, continuation lines indented."""
    return [part for line in lines for part in textwrap.wrap(line, width, subsequent_indent="  ")]


#: LaTeX's special characters and what stands for each in text.
LATEX_SPECIAL = {
    "\\": r"\textbackslash{}",
    "&": r"\&",
    "%": r"\%",
    "$": r"\$",
    "#": r"\#",
    "_": r"\_",
    "{": r"\{",
    "}": r"\}",
    "~": r"\textasciitilde{}",
    "^": r"\textasciicircum{}",
    # in text mode under the default font encoding (OT1), < and > print as inverted ! and ?
    "<": "$<$",
    ">": "$>$",
}
#: A cell siunitx reads as a number.
PLAIN_NUMBER = re.compile(r"-?\d+(\.\d+)?")
#: The LaTeX column type of each kind of column (numbers: siunitx ``S``).
LATEX_COLUMN = {"text": "l", "number": "S", "interval": "r"}


def latex_escape(text: str) -> str:
    return "".join(LATEX_SPECIAL.get(char, char) for char in text)


def to_latex(view: TableView) -> str:
    """The view through pandas' Styler: booktabs rules, siunitx ``S`` columns for single
    numbers, marked cells ``\\bfseries``, captioned with the title and note lines; a
    ``longtable`` beyond LATEX_PAGE_ROWS rows; a grouped view's group headings as rows of
    their own over their rows. Needs ``booktabs``, ``siunitx`` and ``longtable``."""
    groups = view.group_columns()
    kept = [k for k, c in enumerate(view.shown_columns()) if c not in groups]
    kinds = [view.column_kinds()[k] for k in kept]
    text = view.text_frame().drop(columns=groups).map(latex_escape)
    for column, kind in zip(text.columns, kinds, strict=True):
        if kind == "number":  # siunitx reads a braced cell as text ("--", "$<$0.001")
            text[column] = [c if PLAIN_NUMBER.fullmatch(c) else f"{{{c}}}" for c in text[column]]
    text.columns = [latex_escape(c) for c in text.columns]
    mask = view.mark_mask()[:, kept]
    styler = text.style.hide(axis="index").apply(
        lambda cells: np.where(mask, "bfseries: ;", ""), axis=None
    )
    long = len(text) > LATEX_PAGE_ROWS
    caption = latex_escape(" ".join([f"{view.title}.", *view.note_lines("Bold")]))
    latex = styler.to_latex(
        column_format="".join(LATEX_COLUMN[kind] for kind in kinds), hrules=True, siunitx=True,
        caption=caption, label=f"tab:{view.name}", position=None if long else "htbp",
        environment="longtable" if long else None,
    )  # fmt: skip
    return _latex_group_heads(latex, view.group_heads(), len(kinds)) if groups else latex


def _latex_group_heads(latex: str, heads: list[str | None], width: int) -> str:
    """``latex`` (a table of ``len(heads)`` body rows, the last rows that end in ``\\\\``) with
    a row spanning its ``width`` columns before each row that has a head."""
    lines = latex.split("\n")
    ends = [k for k, line in enumerate(lines) if line.endswith("\\\\")]
    rows = ends[len(ends) - len(heads) :]
    for k, head in reversed(list(zip(rows, heads, strict=True))):
        if head is not None:
            lines.insert(k, f"\\multicolumn{{{width}}}{{l}}{{\\itshape {latex_escape(head)}}} \\\\")
    return "\n".join(lines)


def to_csv(view: TableView) -> str:
    return view.frame.to_csv(index=False)


def write_views(views: list[TableView], folder: Path) -> list[Path]:
    """Write each view as ``<name>.csv``, ``.md`` and ``.tex`` under ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for view in views:
        for suffix, render in (("csv", to_csv), ("md", to_markdown), ("tex", to_latex)):
            path = folder / f"{view.name}.{suffix}"
            write_text_atomic(path, render(view))
            written.append(path)
    return written


#: Report columns: source column -> (header with unit, digits or None for text, scale factor).
Columns = dict[str, tuple[str, Digits | None, float]]


def scaled_columns(frame: pd.DataFrame, columns: Columns) -> tuple[pd.DataFrame, dict[str, Digits]]:
    """``frame``'s ``columns`` renamed to their headers, numbers scaled; the headers' digits."""
    out = pd.DataFrame(index=frame.index)
    digits = {}
    for source, (header, rule, scale) in columns.items():
        if rule is None:
            out[header] = frame[source].astype(str)
        else:
            out[header] = pd.to_numeric(frame[source], errors="coerce").astype(float) * scale
            digits[header] = rule
    return out, digits
