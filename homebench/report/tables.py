"""Report tables: the run's metric tables with units in the headers, rounded, as CSV / MD / TeX.

Three views of a run's tables (``homebench.evaluation.results``): the method x condition
summary, the return ratio per goal (seed 001, Figure 10 as a table) and the AHC per distance
bin (Figure 9 as a table). Each view is a numeric frame rounded once, so the CSV, Markdown and
LaTeX files (pandas' own writers) show the same numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from homebench.evaluation.results import RunTables
from homebench.fileio import write_text_atomic

MISSING_TEXT = "--"


@dataclass(frozen=True)
class Digits:
    """How a column is rounded: ``decimals`` after the point, or ``significant`` digits."""

    decimals: int | None = None
    significant: int | None = None

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
        rounded = self.round(value)
        return f"{rounded:.{max(0, self._decimals_for(rounded))}f}"


FIXED0, FIXED1, FIXED2, FIXED3 = Digits(0), Digits(1), Digits(2), Digits(3)
SIGNIFICANT3 = Digits(significant=3)


@dataclass(frozen=True)
class TableView:
    """A table ready to print: ``frame`` (rounded, headers with units) and its column digits.

    Columns not in ``digits`` are text (conditions, methods, goals).
    """

    name: str
    title: str
    frame: pd.DataFrame
    digits: dict[str, Digits]

    def text_frame(self) -> pd.DataFrame:
        """Every cell as the text the Markdown and LaTeX tables show."""
        shown = self.frame.copy()
        for column, digits in self.digits.items():
            shown[column] = [digits.text(v) for v in self.frame[column].astype(float)]
        return shown.astype(str)

    def alignment(self) -> list[str]:
        return ["right" if c in self.digits else "left" for c in self.frame.columns]


def make_view(name: str, title: str, frame: pd.DataFrame, digits: dict[str, Digits]) -> TableView:
    frame = frame.reset_index(drop=True)
    for column, rule in digits.items():
        rounded = pd.Series([rule.round(float(v)) for v in frame[column]], dtype=float)
        frame[column] = rounded.astype("Int64") if rule == FIXED0 else rounded
    return TableView(name, title, frame, digits)


#: Summary columns: source column -> (header, digits, scale).
SUMMARY_COLUMNS = {
    "pairs": ("pairs", FIXED0, 1.0),
    "no_estimate_share": ("no estimate [%]", FIXED1, 100.0),
    "mean_ae_deg": ("mean AE [deg]", FIXED2, 1.0),
    "median_ae_deg": ("median AE [deg]", FIXED2, 1.0),
    "ahc": ("AHC", FIXED3, 1.0),
    "rr": ("RR", FIXED3, 1.0),
    "catchment": ("catchment", FIXED3, 1.0),
    "describe_ms": ("describe [ms/image]", SIGNIFICANT3, 1.0),
    "home_ms": ("home [ms/pair]", SIGNIFICANT3, 1.0),
}


def swept(table: pd.DataFrame) -> list[str]:
    """The world factors a table varies over ("style", "seed"), for its row labels."""
    return [c for c in ("style", "seed") if c in table.columns and table[c].notna().any()]


def summary_view(summary: pd.DataFrame) -> TableView:
    """Method x condition summary (per swept style): AE, AHC, RR, share without estimate,
    times."""
    frame = summary[[*swept(summary), "condition", "method"]].copy()
    digits = {}
    for source, (header, rule, scale) in SUMMARY_COLUMNS.items():
        if source in summary.columns:
            frame[header] = summary[source].astype(float) * scale
            digits[header] = rule
    title = "Summary per condition and method (AE over pairs with an estimate)"
    return make_view("summary", title, frame, digits)


def _pivot(table: pd.DataFrame, index: list[str], value: str) -> tuple[pd.DataFrame, list[str]]:
    """``table`` wide: one row per ``index`` value, one column per method (sorted labels)."""
    wide = table.pivot(index=index, columns="method", values=value).sort_index()
    wide.columns = [str(c) for c in wide.columns]
    return wide.reset_index(), list(wide.columns)


def rr_by_goal_view(goals: pd.DataFrame) -> TableView:
    """Return ratio per condition and goal, one column per method (Figure 10 as a table)."""
    factors = swept(goals)
    wide, methods = _pivot(goals, [*factors, "condition", "goal_i", "goal_j"], "rr")
    goal = [f"({i}, {j})" for i, j in zip(wide["goal_i"], wide["goal_j"], strict=True)]
    frame = pd.concat([wide[[*factors, "condition"]], pd.Series(goal, name="goal (i, j)"),
                       wide[methods]], axis=1)  # fmt: skip
    title = "Return ratio per goal (share of start positions that reach the goal)"
    return make_view("rr_by_goal", title, frame, dict.fromkeys(methods, FIXED3))


def ahc_by_distance_view(ahc: pd.DataFrame) -> TableView:
    """AHC per distance bin, one column per method (Figure 9 as a table).

    The "all" row (in the summary) and bins without any pair are left out.
    """
    binned = ahc[(ahc["bin"] != "all") & (ahc["n"] > 0)]
    wide, methods = _pivot(binned, [*swept(binned), "condition", "centre_cm"], "ahc")
    wide = wide.rename(columns={"centre_cm": "distance [cm]"})
    digits = {"distance [cm]": FIXED0, **dict.fromkeys(methods, FIXED3)}
    title = "AHC by distance between current and goal position (bin centres)"
    return make_view("ahc_by_distance", title, wide, digits)


def report_views(tables: RunTables) -> list[TableView]:
    """The three report tables of a run (none when the run has no results)."""
    if tables.pairs.empty:
        return []
    return [
        summary_view(tables.summary),
        rr_by_goal_view(tables.goals),
        ahc_by_distance_view(tables.ahc),
    ]


def to_markdown(view: TableView) -> str:
    text = view.text_frame().to_markdown(
        index=False, disable_numparse=True, colalign=view.alignment()
    )
    return f"**{view.title}**\n\n{text}\n"


def to_latex(view: TableView) -> str:
    """A booktabs tabular inside a table float captioned with the view's title."""
    columns = "".join("r" if a == "right" else "l" for a in view.alignment())
    return view.text_frame().to_latex(
        index=False, escape=True, column_format=columns, caption=view.title,
        label=f"tab:{view.name}", position="htbp",
    )  # fmt: skip


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
