"""Figures of a run's metrics with its conditions side by side, one panel per condition: AHC
against distance (seed 001, Figure 9a-c) and RR per goal (Figure 10a-c); and the time per
describe / home call of one condition.

Fixed scales: RR on [0, 1]; AHC on one range for every panel of a run (:func:`ahc_range`,
passed in), so panels and figures compare at a glance. A run with many conditions takes
several figures of at most ``columns x CONDITION_ROWS`` panels (:func:`ahc_pages`,
:func:`rr_pages`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, LogLocator

from homebench.report.grid.figure_data import Goal, goals_of, pages
from homebench.report.style import (
    CHAR_WIDTH_EM,
    DOUBLE_COLUMN,
    SINGLE_COLUMN,
    MethodStyle,
    font_points,
    in_order,
    legend_below,
    new_figure,
    panel_axes,
)

#: Panels of one row (conditions side by side) and rows of one figure, at most.
CONDITION_COLUMNS = 3
CONDITION_ROWS = 3
#: Inches: height of a row of panels, and of the legend and labels below them.
PANEL_HEIGHT = 2.2
BOTTOM_MARGIN = 0.6
#: AHC axis: its lower end is rounded down to this step; it always ends at 1.
AHC_STEP = 0.1
#: RR axis, fixed.
RR_RANGE = (0.0, 1.0)
#: Width a tick label needs, inches (denser ticks are thinned or turned upright).
TICK_WIDTH = 0.28
#: With more goals than this in a panel, RR is drawn as one box per method instead of bars.
MAX_RR_BARS = 20
#: Bars in one row of RR panels, at most (more: fewer panels side by side).
MAX_BARS_PER_ROW = 72
#: Colour of the CI band in the legend, and of reference lines.
NEUTRAL = "#888888"


@dataclass(frozen=True)
class ConditionPanel:
    """One panel: its ``title`` and the rows of a run's table for its condition (and style)."""

    title: str
    rows: pd.DataFrame


def _condition_figure(
    n: int, columns: int, sharex: bool, wide: bool = False
) -> tuple[Figure, list[Axes], list[tuple[bool, bool]]]:
    """A figure of ``n`` panels, ``columns`` per row; and per panel (first column, bottom).
    One panel per row is a single column wide unless ``wide`` (panels full of bars)."""
    columns = min(n, columns)
    rows = math.ceil(n / columns)
    width = SINGLE_COLUMN if columns == 1 and not wide else DOUBLE_COLUMN
    fig = new_figure((width, rows * PANEL_HEIGHT + BOTTOM_MARGIN))
    axes = panel_axes(fig, n, columns, sharex)
    outer = [(k % columns == 0, k + columns >= n) for k in range(n)]
    return fig, axes, outer


def _panel_width(fig: Figure, columns: int) -> float:
    return fig.get_figwidth() / columns


def _method_handles(methods: Sequence[str], styles: dict[str, MethodStyle]) -> list:
    return [
        Line2D([], [], color=styles[m].colour, marker=styles[m].marker,
               linestyle=styles[m].linestyle, markersize=4, label=m)
        for m in methods
    ]  # fmt: skip


def _letter(k: int) -> str:
    return f"({chr(ord('a') + k)})" if k < 26 else f"({k + 1})"


# --------------------------------------------------------------------------- AHC (Figure 9)


def ahc_range(ahc: pd.DataFrame) -> tuple[float, float]:
    """The AHC axis of every panel of a run: from the lowest AHC or lower CI bound of the
    ``ahc`` table's bins (rounded down to AHC_STEP, and at most 0, so the zero line shows)
    to 1. (-1, 1) when the table holds no value."""
    binned = ahc[ahc["bin"] != "all"] if len(ahc) else ahc
    values = (
        pd.concat([binned["ahc"], binned["ahc_lo"]]).astype(float).dropna()
        if len(binned)
        else pd.Series(dtype=float)
    )
    if values.empty:
        return -1.0, 1.0
    low = math.floor(round(float(values.min()) / AHC_STEP, 9)) * AHC_STEP
    return min(0.0, max(-1.0, low)), 1.0


def ahc_bins(ahc: pd.DataFrame) -> np.ndarray:
    """The distance bins (centres, cm, increasing) the AHC figures of a run show: from the
    first to the last bin of the ``ahc`` table that holds a pair (``n`` > 0) in any condition
    and method, so the axis follows the pairs' distances (a 5 x 7 grid's stop at 180 cm, not
    at the default bins' 390 cm); every bin when none holds a pair."""
    binned = ahc[ahc["bin"] != "all"] if len(ahc) else ahc
    if binned.empty:
        return np.array([], dtype=float)
    centres = binned["centre_cm"].astype(float)
    held = centres[binned["n"].to_numpy() > 0]
    shown = centres.between(held.min(), held.max()) if len(held) else centres.notna()
    return np.unique(centres[shown].to_numpy())


def ahc_pages(panels: Sequence[ConditionPanel]) -> list[list[ConditionPanel]]:
    """``panels`` cut into the AHC figures' pages."""
    return pages(panels, CONDITION_COLUMNS * CONDITION_ROWS)


def _pairs_text(binned: pd.DataFrame) -> tuple[np.ndarray, list[str]]:
    """Bin centres and the pairs in each: "n", or "min-max" when the methods differ."""
    counts = binned.groupby("centre_cm")["n"].agg(["min", "max"])
    texts = [f"{lo}" if lo == hi else f"{lo}-{hi}" for lo, hi in zip(counts["min"], counts["max"],
                                                                       strict=True)]  # fmt: skip
    return counts.index.to_numpy(dtype=float), texts


def _draw_ahc(
    ax: Axes, rows: pd.DataFrame, styles: dict[str, MethodStyle], centres: np.ndarray
) -> None:
    """One line per method with its 95 % CI band over the bins ``centres`` (cm); pairs per
    bin on the top axis; the x axis half a bin beyond the first and last centre."""
    binned = rows[(rows["bin"] != "all") & rows["centre_cm"].isin(centres)]
    drawn = binned[binned["n"] > 0]
    for method, group in drawn.groupby("method", sort=True):
        style = styles[str(method)]
        x = group["centre_cm"].to_numpy(dtype=float)
        ax.fill_between(x, group["ahc_lo"].to_numpy(dtype=float),
                        group["ahc_hi"].to_numpy(dtype=float), color=style.colour, alpha=0.18,
                        linewidth=0)  # fmt: skip
        ax.plot(x, group["ahc"].to_numpy(dtype=float), color=style.colour, marker=style.marker,
                markersize=3, linestyle=style.linestyle, linewidth=1.0, clip_on=False)  # fmt: skip
    centres, counts = _pairs_text(binned)
    top = ax.secondary_xaxis("top")
    top.set_xticks(centres, counts, rotation=90, fontsize=5.5)
    top.tick_params(length=2, pad=1)
    ax.set_xticks(centres)
    if len(centres):
        half = (np.diff(centres).min() if len(centres) > 1 else centres[0]) / 2
        ax.set_xlim(centres[0] - half, centres[-1] + half)
    ax.axhline(0.0, color=NEUTRAL, linewidth=0.6)
    ax.grid(True, alpha=0.3)


def _thin_ticks(ax: Axes, centres: np.ndarray, width: float) -> None:
    """Label every k-th bin centre so the labels fit ``width`` inches."""
    step = max(1, math.ceil(len(centres) * TICK_WIDTH / width))
    labels = [f"{c:g}" if k % step == 0 else "" for k, c in enumerate(centres)]
    ax.set_xticks(centres, labels)


def ahc_figure(
    panels: Sequence[ConditionPanel],
    styles: dict[str, MethodStyle],
    limits: tuple[float, float],
    label: str = "AHC",
    centres: np.ndarray | None = None,
) -> Figure:
    """AHC per distance bin, one panel per condition, one line per method with its 95 % CI
    band (``ahc_lo`` to ``ahc_hi``); the pairs per bin (``n``) along the top axis.

    ``panels``: rows of :func:`homebench.analysis.tables.ahc_table` each; ``limits``: the
    y-range of every panel (:func:`ahc_range` of the whole run); ``label``: the AHC axis's;
    ``centres``: the bins shown in every panel (cm; default :func:`ahc_bins` of the panels'
    rows; pass the whole run's).
    """
    if centres is None:
        centres = ahc_bins(pd.concat([panel.rows for panel in panels], ignore_index=True))
    fig, axes, outer = _condition_figure(len(panels), CONDITION_COLUMNS, sharex=False)
    width = _panel_width(fig, min(len(panels), CONDITION_COLUMNS))
    methods: set[str] = set()
    for k, (ax, panel, (first, bottom)) in enumerate(zip(axes, panels, outer, strict=True)):
        _draw_ahc(ax, panel.rows, styles, centres)
        methods |= set(panel.rows["method"])
        ax.set_ylim(*limits)
        _thin_ticks(ax, centres, width)
        ax.set_title(f"{_letter(k)} {panel.title}", loc="left")
        if bottom:
            ax.set_xlabel("distance C to H [cm]")
        if first:
            ax.set_ylabel(label)
    handles = _method_handles(in_order(styles, methods), styles)
    handles.append(Patch(color=NEUTRAL, alpha=0.3, label="95 % CI"))
    legend_below(fig, handles, 6)
    return fig


# --------------------------------------------------------------------------- RR (Figure 10)


@dataclass(frozen=True)
class RRPanel:
    """One RR panel: ``title``, the goal table's rows (RR per goal and method) and the summary
    table's rows (mean RR over the goals with its CI, ``rr``, ``rr_lo``, ``rr_hi``)."""

    title: str
    goals: pd.DataFrame
    summary: pd.DataFrame


def _rr_bars(panels: Sequence[RRPanel]) -> int:
    """The most bars of a panel (methods x (goals + the mean))."""
    return max(
        (p.goals["method"].nunique() * (min(_n_goals(p), MAX_RR_BARS) + 1) for p in panels),
        default=1,
    )


def _rr_columns(panels: Sequence[RRPanel]) -> int:
    """Panels side by side: as many as keep a row under MAX_BARS_PER_ROW bars."""
    return max(1, min(CONDITION_COLUMNS, MAX_BARS_PER_ROW // max(_rr_bars(panels), 1)))


def _n_goals(panel: RRPanel) -> int:
    return len(set(goals_of(panel.goals)))


def rr_pages(panels: Sequence[RRPanel]) -> list[list[RRPanel]]:
    """``panels`` cut into the RR figures' pages."""
    return pages(panels, _rr_columns(panels) * CONDITION_ROWS)


def _offsets(n: int) -> tuple[np.ndarray, float]:
    width = 0.8 / n
    return (np.arange(n) - (n - 1) / 2) * width, width


def _draw_mean(
    ax: Axes, x: float, summary: pd.DataFrame, methods: list[str], styles: dict[str, MethodStyle]
) -> None:
    """Each method's mean RR over the goals as a bar at ``x`` with its 95 % CI."""
    offsets, width = _offsets(len(methods))
    for offset, method in zip(offsets, methods, strict=True):
        row = summary[summary["method"] == method]
        if row.empty or pd.isna(row["rr"].iloc[0]):
            continue
        rr, lo, hi = (float(row[c].iloc[0]) for c in ("rr", "rr_lo", "rr_hi"))
        style = styles[method]
        ax.bar(x + offset, rr, width, color=style.colour, hatch=style.hatch,
               edgecolor="white", linewidth=0)  # fmt: skip
        if not (math.isnan(lo) or math.isnan(hi)):
            ax.errorbar(x + offset, rr, yerr=[[rr - lo], [hi - rr]], color="black",
                        linewidth=0.8, capsize=2, clip_on=False)  # fmt: skip


def _draw_rr_bars(
    ax: Axes, goals: pd.DataFrame, keys: list[Goal], methods: list[str],
    styles: dict[str, MethodStyle],
) -> None:  # fmt: skip
    """Bars per goal and method; "n/a" where the goal's field does not cover the grid."""
    position = {key: k for k, key in enumerate(keys)}
    offsets, width = _offsets(len(methods))
    for offset, method in zip(offsets, methods, strict=True):
        rows = goals[goals["method"] == method]
        x = np.array([position[g] for g in goals_of(rows)], dtype=float) + offset
        rr = rows["rr"].to_numpy(dtype=float)
        style = styles[method]
        ax.bar(x, np.nan_to_num(rr), width, color=style.colour, hatch=style.hatch,
               edgecolor="white", linewidth=0)  # fmt: skip
        for xk in x[np.isnan(rr)]:
            ax.text(xk, 0.02, "n/a", rotation=90, ha="center", va="bottom", fontsize=5.5)


def _draw_rr_boxes(
    ax: Axes, goals: pd.DataFrame, methods: list[str], styles: dict[str, MethodStyle]
) -> None:
    """One box of the goals' RR per method (at x = 0)."""
    offsets, width = _offsets(len(methods))
    for offset, method in zip(offsets, methods, strict=True):
        values = goals.loc[goals["method"] == method, "rr"].dropna().to_numpy(dtype=float)
        if not values.size:
            continue
        parts = ax.boxplot([values], positions=[offset], widths=0.9 * width, patch_artist=True,
                           flierprops={"markersize": 2}, manage_ticks=False)  # fmt: skip
        parts["boxes"][0].set(facecolor=styles[method].colour, hatch=styles[method].hatch)
        parts["medians"][0].set_color("black")


def rr_figure(panels: Sequence[RRPanel], styles: dict[str, MethodStyle]) -> Figure:
    """Return ratio per goal and method, one panel per condition; right of a dotted line, each
    method's mean RR over the goals with its 95 % CI. With more than MAX_RR_BARS goals, a box
    of the goals' RR per method replaces the bars."""
    columns = _rr_columns(panels)
    wide = _rr_bars(panels) > MAX_BARS_PER_ROW // CONDITION_COLUMNS
    fig, axes, outer = _condition_figure(len(panels), columns, sharex=False, wide=wide)
    width = _panel_width(fig, min(len(panels), columns))
    methods_shown: set[str] = set()
    for k, (ax, panel, (first, bottom)) in enumerate(zip(axes, panels, outer, strict=True)):
        methods = in_order(styles, panel.goals["method"])
        methods_shown |= set(methods)
        keys = sorted(set(goals_of(panel.goals)))
        if len(keys) <= MAX_RR_BARS:
            _draw_rr_bars(ax, panel.goals, keys, methods, styles)
            one_world = len({(g.style, g.seed) for g in keys}) == 1  # the title names it
            ticks = [f"({g.i}, {g.j})" if one_world else g.text for g in keys]
        else:
            _draw_rr_boxes(ax, panel.goals, methods, styles)
            keys, ticks = [keys[0]], [f"{len(set(goals_of(panel.goals)))} goals"]
        mean_x = len(keys) + 0.2
        ax.axvline(mean_x - 0.6, color=NEUTRAL, linewidth=0.6, linestyle=":")
        _draw_mean(ax, mean_x, panel.summary, methods, styles)
        label_width = CHAR_WIDTH_EM * font_points("xtick.labelsize") / 72.0  # inches a char
        upright = sum(len(t) + 2 for t in [*ticks, "mean"]) * label_width > width
        ax.set_xticks([*range(len(keys)), mean_x], [*ticks, "mean"],
                      rotation=90 if upright else 0)  # fmt: skip
        ax.set_xlim(-0.6, mean_x + 0.6)
        ax.set_ylim(*RR_RANGE)
        ax.grid(True, axis="y", alpha=0.3)
        ax.set_title(f"{_letter(k)} {panel.title}", loc="left")
        if bottom:
            ax.set_xlabel("goal (i, j)")
        if first:
            ax.set_ylabel("RR")
    handles = [
        Patch(facecolor=styles[m].colour, hatch=styles[m].hatch, edgecolor="white", label=m)
        for m in in_order(styles, methods_shown)
    ]
    handles.append(Line2D([], [], color="black", marker="|", linestyle="", label="95 % CI"))
    legend_below(fig, handles, 6)
    return fig


# --------------------------------------------------------------------------- timing


def _boxes(
    ax: Axes,
    data: list[np.ndarray],
    methods: list[str],
    styles: dict[str, MethodStyle],
    ticks: list[str],
) -> None:
    """One box per method in its colour, ``ticks`` below; methods with no value keep a slot."""
    shown = [values if values.size else np.array([np.nan]) for values in data]
    parts = ax.boxplot(shown, patch_artist=True, widths=0.6, flierprops={"markersize": 2})
    for patch, method in zip(parts["boxes"], methods, strict=True):
        patch.set(facecolor=styles[method].colour, hatch=styles[method].hatch)
    for median in parts["medians"]:
        median.set_color("black")
    ax.set_xticks(range(1, len(methods) + 1), ticks, rotation=90 if len(methods) > 3 else 0)


def timing_figure(
    describe_ms: pd.DataFrame, home_ms: pd.DataFrame, styles: dict[str, MethodStyle]
) -> Figure:
    """Time per call on a log axis, one box per method (quartiles, median line): describe per
    image, home per pair.

    ``describe_ms``, ``home_ms``: frames with columns ``method`` and ``describe_ms`` /
    ``home_ms`` (milliseconds), one row per call.
    """
    fig = new_figure((DOUBLE_COLUMN, PANEL_HEIGHT + BOTTOM_MARGIN + 0.4))
    axes = fig.subplots(1, 2, sharey=True)
    methods = in_order(styles, [*describe_ms["method"], *home_ms["method"]])
    for ax, frame, column, label in (
        (axes[0], describe_ms, "describe_ms", "describe (per image)"),
        (axes[1], home_ms, "home_ms", "home (per pair)"),
    ):
        data = [frame.loc[frame["method"] == m, column].to_numpy(dtype=float) for m in methods]
        positive = [values[values > 0] for values in data]
        medians = [f"{np.median(v):.3g} ms" if v.size else "no data" for v in positive]
        ticks = [f"{m}\nmedian {t}" for m, t in zip(methods, medians, strict=True)]
        _boxes(ax, positive, methods, styles, ticks)
        ax.set_yscale("log")
        ax.yaxis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        for axis in (ax.yaxis.set_major_formatter, ax.yaxis.set_minor_formatter):
            axis(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_title(label)
        ax.grid(True, axis="y", which="both", alpha=0.3)
    axes[0].set_ylabel("time per call [ms] (log)")
    return fig
