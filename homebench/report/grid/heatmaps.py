"""Overview heat maps of a sweep: method x condition, one map per metric, each cell's value
written in it.

A run over many conditions (or styles) would fill hundreds of pages with per-condition
figures; these maps show its summary table (:func:`homebench.analysis.tables.summary_table`)
on a page per metric instead. Colour scales are fixed, so maps of different runs compare by
eye: AHC -1 to 1 (its whole range: 0 is a mean AE of 90 deg), RR 0 to 1, mean AE 0 to 100 deg
(larger errors take the end colour), the share without an estimate 0 to 100 %. The colour of a
better value is the same in every map. Where a method abstains on some pair, the AHC with a
missing estimate as 90 deg and the share without an estimate follow the AHC's map, so that a
method that abstains where it is unsure does not look better than it homes.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.colors import Colormap
from matplotlib.figure import Figure

from homebench.config import AhcConfig
from homebench.report.style import DOUBLE_COLUMN, MAX_FIGURE_HEIGHT, MISSING_COLOUR, new_figure
from homebench.report.tables import DEFAULT_AHC, ahc_header, swept

#: Section heading of the overview figures.
OVERVIEW_SECTION = "Overview"
#: Most columns (conditions) in one heat map; more continue on another map.
MAX_MAP_COLUMNS = 12
#: Height of a method's row, and of the rest of the figure (inches).
ROW_HEIGHT = 0.3
FRAME_HEIGHT = 2.0
#: Cell colours whose luminance is above this get black text, the others white.
LIGHT = 0.5


@dataclass(frozen=True)
class HeatMetric:
    """A summary column drawn as a heat map: its label, fixed colour range, value format,
    colour map (reversed for a metric where smaller is better), which end of the colour bar
    stands for values beyond the range (matplotlib's ``extend``), the factor from the
    column's values to the drawn ones, and what the caption adds."""

    column: str
    label: str
    vmin: float
    vmax: float
    fmt: str
    cmap: str
    extend: str = "neither"
    scale: float = 1.0
    note: str = ""


HEAT_METRICS = (
    HeatMetric("ahc", "AHC", -1.0, 1.0, "{:.2f}", "viridis"),
    HeatMetric(
        "ahc_missing90", "AHC (no est. = 90 deg)", -1.0, 1.0, "{:.2f}", "viridis",
        note=" A pair without an estimate counts as 90 deg, so that abstaining gains nothing.",
    ),
    HeatMetric(
        "no_estimate_share", "no estimate [%]", 0.0, 100.0, "{:.1f}", "viridis_r", scale=100.0,
        note=" The pairs the paper's AHC leaves out.",
    ),
    HeatMetric("rr", "RR", 0.0, 1.0, "{:.2f}", "viridis"),
    HeatMetric("mean_ae_deg", "mean AE [deg]", 0.0, 100.0, "{:.1f}", "viridis_r", "max"),
)  # fmt: skip
#: Maps drawn only where some method lacks an estimate on some pair (else they repeat the
#: AHC's map and show zeros).
ABSTENTION_METRICS = ("ahc_missing90", "no_estimate_share")


def heat_metrics(summary: pd.DataFrame, ahc: AhcConfig = DEFAULT_AHC) -> list[HeatMetric]:
    """The maps of ``summary`` (the summary's columns; ABSTENTION_METRICS only where a method
    abstains), labelled by the run's AHC definition (``ahc``)."""
    abstains = "no_estimate_share" in summary and bool((summary["no_estimate_share"] > 0).any())
    return [
        replace(metric, label=ahc_header(metric.label, ahc))
        for metric in HEAT_METRICS
        if metric.column in summary.columns
        and (abstains or metric.column not in ABSTENTION_METRICS)
    ]


def _factors(summary: pd.DataFrame) -> list[str]:
    """The columns naming a map's column: "style" when the run swept styles, "condition"."""
    return [*(["style"] if "style" in swept(summary) else []), "condition"]


def heatmap_columns(summary: pd.DataFrame, conditions: Sequence[str]) -> list[tuple[str, ...]]:
    """The maps' columns: (style, condition) or (condition,) with results, styles sorted,
    conditions in ``conditions``' order (the config's)."""
    order = {c: k for k, c in enumerate(conditions)}
    keys = summary[_factors(summary)]
    unique = {tuple(str(v) for v in row) for row in keys.itertuples(index=False)}
    return sorted(unique, key=lambda key: (key[:-1], order.get(key[-1], len(order)), key[-1]))


def _grid(
    summary: pd.DataFrame, columns: list[tuple[str, ...]], metric: HeatMetric
) -> pd.DataFrame:
    """``metric``'s values as drawn (scaled) as methods (in ``summary``'s row order) x
    ``columns``; NaN where there is no value."""
    keys = summary[_factors(summary)].itertuples(index=False)
    keyed = summary.assign(key=[tuple(str(v) for v in row) for row in keys])
    wide = keyed.pivot(index="method", columns="key", values=metric.column)
    rows = pd.unique(keyed["method"])
    return wide.reindex(index=rows, columns=pd.Index(columns, tupleize_cols=False)) * metric.scale


def _cell_colour(cmap: Colormap, metric: HeatMetric, value: float) -> str:
    """Black or white, whichever reads better on the cell of ``value``."""
    position = (min(max(value, metric.vmin), metric.vmax) - metric.vmin) / (
        metric.vmax - metric.vmin
    )
    r, g, b, _ = cmap(position)
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > LIGHT else "white"


def heatmap_figure(values: pd.DataFrame, metric: HeatMetric) -> Figure:
    """One heat map: ``values`` (methods x columns of (style, condition) keys) coloured on the
    metric's fixed scale, each value written in its cell ("n/a" on grey without one)."""
    rows, n_columns = values.shape
    height = min(FRAME_HEIGHT + ROW_HEIGHT * rows, MAX_FIGURE_HEIGHT)
    fig = new_figure((DOUBLE_COLUMN, height))
    ax = fig.add_subplot()
    cmap = mpl.colormaps[metric.cmap].with_extremes(bad=MISSING_COLOUR)
    data = np.ma.masked_invalid(values.to_numpy(dtype=float))
    mesh = ax.pcolormesh(data, cmap=cmap, vmin=metric.vmin, vmax=metric.vmax)
    fontsize = 7 if n_columns <= 6 else 6
    for (r, c), value in np.ndenumerate(values.to_numpy(dtype=float)):
        text, colour = ("n/a", "black") if math.isnan(value) else (
            metric.fmt.format(value), _cell_colour(cmap, metric, value))  # fmt: skip
        ax.text(c + 0.5, r + 0.5, text, ha="center", va="center", fontsize=fontsize,
                color=colour)  # fmt: skip
    ax.set_yticks(np.arange(rows) + 0.5, [str(m) for m in values.index])
    labels = [" / ".join(key) for key in values.columns]
    tilted = n_columns > 4
    ax.set_xticks(np.arange(n_columns) + 0.5, labels, rotation=40 if tilted else 0,
                  ha="right" if tilted else "center", rotation_mode="anchor")  # fmt: skip
    ax.invert_yaxis()
    ax.set_ylabel("method")
    ax.set_xlabel("style / condition (current-goal)" if len(values.columns[0]) == 2
                  else "condition (current-goal)")  # fmt: skip
    ax.tick_params(length=0)
    fig.colorbar(mesh, ax=ax, label=f"{metric.label} (fixed scale)", extend=metric.extend,
                 pad=0.01)  # fmt: skip
    return fig


def heatmap_figures(
    summary: pd.DataFrame,
    conditions: Sequence[str],
    seeds_pooled: bool = False,
    ahc: AhcConfig = DEFAULT_AHC,
) -> Iterator[tuple[str, str, str, Figure]]:
    """(file stem, section, caption, figure) of each of :func:`heat_metrics`' maps,
    MAX_MAP_COLUMNS columns per map; nothing when ``summary`` is empty. ``seeds_pooled``: the
    run swept world seeds, which each cell pools (the caption says so); ``ahc``: the run's
    AHC settings."""
    columns = heatmap_columns(summary, conditions) if not summary.empty else []
    chunks = [columns[k : k + MAX_MAP_COLUMNS] for k in range(0, len(columns), MAX_MAP_COLUMNS)]
    pooled = ", world seeds pooled," if seeds_pooled else ""
    for metric in heat_metrics(summary, ahc):
        for part, chunk in enumerate(chunks, start=1):
            more = f" (part {part} of {len(chunks)})" if len(chunks) > 1 else ""
            caption = (
                f"{metric.label} of each method (rows) under each condition (columns){more}"
                f"{pooled} as in the summary table.{metric.note} The colour scale is fixed at "
                f"{metric.vmin:g} to {metric.vmax:g} for every run; grey cells (n/a) have no "
                "value."
            )
            stem = f"heatmap_{metric.column}" + (f"_{part}" if len(chunks) > 1 else "")
            grid = _grid(summary, chunk, metric)
            yield stem, OVERVIEW_SECTION, caption, heatmap_figure(grid, metric)
