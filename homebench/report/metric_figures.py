"""Figures of one condition's metrics: AHC against distance (seed 001, Figure 9), RR per goal
(Figure 10) and the time per describe / home call."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator

from homebench.report.style import PLOT_SIZE, MethodStyle, legend_right, new_figure, set_title

#: With more goals than this, RR is drawn as one box per method instead of bars per goal.
MAX_RR_BARS = 20
#: With more bars than this, their value labels are turned upright.
MAX_FLAT_LABELS = 24


def ahc_figure(ahc: pd.DataFrame, styles: dict[str, MethodStyle], title: str) -> Figure:
    """AHC per distance bin, one line per method.

    ``ahc``: rows of :func:`homebench.evaluation.results.ahc_table` for one condition; the
    "all" row and bins without pairs are left out.
    """
    fig = new_figure(PLOT_SIZE)
    ax = fig.add_subplot()
    binned = ahc[(ahc["bin"] != "all") & (ahc["n"] > 0)]
    for method, rows in binned.groupby("method", sort=True):
        style = styles[str(method)]
        ax.plot(rows["centre_cm"], rows["ahc"], color=style.colour, marker=style.marker,
                linestyle=style.linestyle, label=str(method))  # fmt: skip
    lowest = float(np.nanmin(binned["ahc"])) if binned["ahc"].notna().any() else 0.0
    ax.set_ylim(min(0.0, math.floor(lowest * 10) / 10) - 0.05, 1.05)
    ax.axhline(0.0, color="#888888", linewidth=0.8)
    ax.set_xticks(sorted(binned["centre_cm"].unique()))
    ax.set_xlabel("distance between current and goal position [cm]")
    ax.set_ylabel("AHC = cos(mean AE)")
    ax.grid(True, alpha=0.3)
    legend_right(ax, "method")
    set_title(fig, title)
    return fig


def rr_figure(goals: pd.DataFrame, styles: dict[str, MethodStyle], title: str) -> Figure:
    """Return ratio per goal and method: grouped bars, or one box per method for many goals.

    ``goals``: rows of :func:`homebench.evaluation.results.goal_table` for one condition.
    Goals whose RR could not be computed (the field does not cover the grid) show "n/a".
    """
    fig = new_figure(PLOT_SIZE)
    ax = fig.add_subplot()
    methods = sorted(goals["method"].unique())
    keys = sorted({(int(i), int(j)) for i, j in zip(goals["goal_i"], goals["goal_j"],
                                                     strict=True)})  # fmt: skip
    if len(keys) <= MAX_RR_BARS:
        _rr_bars(ax, goals, methods, keys, styles)
    else:
        _rr_boxes(ax, goals, methods, styles)
    ax.set_ylim(0.0, 1.15)
    ax.set_ylabel("RR (share of starts reaching the goal)")
    ax.grid(True, axis="y", alpha=0.3)
    set_title(fig, title)
    return fig


def _rr_bars(
    ax: Axes,
    goals: pd.DataFrame,
    methods: list[str],
    keys: list[tuple[int, int]],
    styles: dict[str, MethodStyle],
) -> None:
    width = 0.8 / len(methods)
    crowded = len(methods) * len(keys) > MAX_FLAT_LABELS
    position = {key: k for k, key in enumerate(keys)}
    for m, method in enumerate(methods):
        rows = goals[goals["method"] == method]
        x = np.array([position[(int(i), int(j))] for i, j in zip(rows["goal_i"], rows["goal_j"],
                                                                 strict=True)])  # fmt: skip
        x = x + (m - (len(methods) - 1) / 2) * width
        rr = rows["rr"].to_numpy(dtype=float)
        bars = ax.bar(x, np.nan_to_num(rr), width, color=styles[method].colour, label=method)
        ax.bar_label(bars, labels=[f"{v:.2f}" if not np.isnan(v) else "" for v in rr],
                     fontsize=6, padding=2, rotation=90 if crowded else 0)  # fmt: skip
        for xk in x[np.isnan(rr)]:
            ax.text(xk, 0.02, "n/a", rotation=90, ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(keys)), [f"({i}, {j})" for i, j in keys])
    ax.set_xlabel("goal (i, j)")
    legend_right(ax, "method")


def _rr_boxes(
    ax: Axes, goals: pd.DataFrame, methods: list[str], styles: dict[str, MethodStyle]
) -> None:
    data = [goals.loc[goals["method"] == m, "rr"].dropna().to_numpy() for m in methods]
    n_goals = goals[["goal_i", "goal_j"]].drop_duplicates().shape[0]
    _boxes(ax, data, methods, styles, methods)
    ax.set_xlabel(f"method (RR over {n_goals} goals; diamond = mean)")
    for k, values in enumerate(data):
        if values.size:
            ax.scatter([k + 1], [values.mean()], marker="D", color="black", zorder=3, s=18)


def _boxes(
    ax: Axes,
    data: list[np.ndarray],
    methods: list[str],
    styles: dict[str, MethodStyle],
    ticks: list[str],
) -> None:
    """One box per method in its colour, ``ticks`` below; methods with no value keep a slot."""
    shown = [values if values.size else np.array([np.nan]) for values in data]
    parts = ax.boxplot(shown, patch_artist=True, widths=0.6, flierprops={"markersize": 3})
    for patch, method in zip(parts["boxes"], methods, strict=True):
        patch.set_facecolor(styles[method].colour)
    for median in parts["medians"]:
        median.set_color("black")
    ax.set_xticks(range(1, len(methods) + 1), ticks, rotation=20 if len(methods) > 4 else 0)


def timing_figure(
    describe_ms: pd.DataFrame,
    home_ms: pd.DataFrame,
    styles: dict[str, MethodStyle],
    title: str,
) -> Figure:
    """Time per call on a log axis, one box per method: describe per image, home per pair.

    ``describe_ms``, ``home_ms``: frames with columns ``method`` and ``describe_ms`` /
    ``home_ms`` (milliseconds), one row per call.
    """
    fig = new_figure(PLOT_SIZE)
    axes = fig.subplots(1, 2, sharey=True)
    methods = sorted(set(describe_ms["method"]) | set(home_ms["method"]))
    for ax, frame, column, label in (
        (axes[0], describe_ms, "describe_ms", "describe: time per image [ms]"),
        (axes[1], home_ms, "home_ms", "home: time per pair [ms]"),
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
    axes[0].set_ylabel("milliseconds (log scale); box: quartiles, line: median")
    set_title(fig, title)
    return fig
