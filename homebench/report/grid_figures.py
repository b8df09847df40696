"""Figures on the capture grid, one panel per method side by side: home-vector fields (seed 001,
Figure 7) and AE heat maps (Figure 8). Axes are world metres, x to the right, y up."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import MaxNLocator

from homebench.geometry import Grid
from homebench.report.figure_data import GoalPanel
from homebench.report.style import (
    FAILED_COLOUR,
    GOAL_COLOUR,
    MAX_COLUMNS,
    MISSING_COLOUR,
    PAGE_SIZE,
    MethodStyle,
    new_figure,
    outer_panel,
    panel_axes,
    set_title,
)

#: Height (inches) the titles, labels and legend of a grid figure take, and its least height.
GRID_FIGURE_MARGIN = 1.8
MIN_GRID_FIGURE_HEIGHT = 4.0
#: Arrow length as a share of the grid spacing.
ARROW_LENGTH = 0.6
#: AE colour map (dark = small error) and the step the shared scale's top is rounded up to.
AE_CMAP = "viridis"
AE_SCALE_STEP_DEG = 10.0


def _grid_figure(n: int, grid: Grid) -> tuple[Figure, list[Axes]]:
    """A page-wide figure for ``n`` grid panels, no taller than the panels need."""
    columns = min(n, MAX_COLUMNS)
    rows = math.ceil(n / columns)
    panel_width = PAGE_SIZE[0] / columns
    aspect = grid.shape[1] / grid.shape[0]
    height = min(PAGE_SIZE[1], rows * panel_width * aspect + GRID_FIGURE_MARGIN)
    fig = new_figure((PAGE_SIZE[0], max(height, MIN_GRID_FIGURE_HEIGHT)))
    return fig, panel_axes(fig, n)


def _frame_axes(ax: Axes, grid: Grid, first_column: bool, bottom_row: bool) -> None:
    """Limits half a spacing beyond the grid, equal aspect, labels on the outer panels."""
    (x0, y0), (x1, y1) = grid.position(0, 0), grid.position(grid.shape[0] - 1, grid.shape[1] - 1)
    half = grid.spacing / 2
    ax.set_xlim(x0 - half, x1 + half)
    ax.set_ylim(y0 - half, y1 + half)
    ax.set_aspect("equal")
    # no tick on the edges: neighbouring panels' edge labels would run into each other
    ax.xaxis.set_major_locator(MaxNLocator(nbins=6, prune="both"))
    if bottom_row:
        ax.set_xlabel("x [m]")
    if first_column:
        ax.set_ylabel("y [m]")


def _goal_xy(panel: GoalPanel) -> tuple[float, float]:
    x, y = panel.field.goal_xy
    return float(x), float(y)


def goal_subtitle(goal: tuple[int, int], grid: Grid) -> str:
    x, y = grid.position(*goal)
    return f"goal {goal} at ({x:.2f}, {y:.2f}) m"


def _draw_field(ax: Axes, panel: GoalPanel, style: MethodStyle) -> None:
    grid = panel.field.grid
    xy = grid.position(*np.indices(grid.shape))
    angles = panel.field.angles
    has = panel.tested & ~np.isnan(angles)
    length = ARROW_LENGTH * grid.spacing
    tested = xy[panel.tested]
    ax.scatter(tested[:, 0], tested[:, 1], marker="s", s=10, color=MISSING_COLOUR, zorder=1)
    succeeded, failed = has & ~panel.rr_failed, has & panel.rr_failed
    for mask, colour in ((succeeded, style.colour), (failed, FAILED_COLOUR)):
        if not mask.any():
            continue
        u, v = length * np.cos(angles[mask]), length * np.sin(angles[mask])
        ax.quiver(xy[mask][:, 0], xy[mask][:, 1], u, v, color=colour, angles="xy",
                  scale_units="xy", scale=1, width=0.008, headwidth=4, headlength=4.5,
                  headaxislength=4, pivot="tail", zorder=3)  # fmt: skip
    missing = xy[panel.no_estimate]
    ax.scatter(missing[:, 0], missing[:, 1], marker="x", s=30, color=FAILED_COLOUR, zorder=4)
    gx, gy = _goal_xy(panel)
    ax.scatter([gx], [gy], marker="s", s=80, color=GOAL_COLOUR, edgecolor="black", zorder=5)


def _field_legend(fig: Figure) -> None:
    handles = [
        Line2D([], [], marker="s", ls="", color=GOAL_COLOUR, markersize=8, label="goal"),
        Line2D([], [], marker="s", ls="", color=MISSING_COLOUR, markersize=4,
               label="current position"),
        Line2D([], [], marker=r"$\rightarrow$", ls="", color="#555555", markersize=12,
               label="home vector (method colour: RR trial from here succeeds)"),
        Line2D([], [], marker=r"$\rightarrow$", ls="", color=FAILED_COLOUR, markersize=12,
               label="RR trial from here fails"),
        Line2D([], [], marker="x", ls="", color=FAILED_COLOUR, markersize=7, label="no estimate"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)


def _panel_title(panel: GoalPanel, extra: str) -> str:
    rr = "RR n/a" if math.isnan(panel.rr) else f"RR {panel.rr:.2f}"
    return f"{panel.label}\n{extra}, {rr}"


def field_figure(panels: Sequence[GoalPanel], styles: dict[str, MethodStyle], title: str) -> Figure:
    """Home-vector fields of several methods towards one goal, side by side.

    Arrows point along each position's estimated home direction (world frame), in the method's
    colour where the return-ratio trial started there succeeds, dark where it fails.
    """
    fig, axes = _grid_figure(len(panels), panels[0].field.grid)
    for k, (ax, panel) in enumerate(zip(axes, panels, strict=True)):
        _draw_field(ax, panel, styles[panel.label])
        _frame_axes(ax, panel.field.grid, *outer_panel(k, len(panels)))
        n_missing = int(panel.no_estimate.sum())
        ax.set_title(_panel_title(panel, f"{n_missing} without estimate"))
    _field_legend(fig)
    set_title(fig, title)
    return fig


def shared_ae_scale(panels: Sequence[GoalPanel]) -> float:
    """Top of the AE colour scale (degrees): the largest AE of the panels, rounded up."""
    values = np.concatenate([p.ae_deg[~np.isnan(p.ae_deg)] for p in panels])
    top = float(values.max()) if values.size else 0.0
    return float(min(180.0, max(AE_SCALE_STEP_DEG, math.ceil(top / AE_SCALE_STEP_DEG)
                                * AE_SCALE_STEP_DEG)))  # fmt: skip


def _cell_edges(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    i_edges = np.arange(grid.shape[0] + 1) - 0.5
    j_edges = np.arange(grid.shape[1] + 1) - 0.5
    x = grid.origin[0] + i_edges * grid.spacing
    y = grid.origin[1] + j_edges * grid.spacing
    return x, y


def ae_figure(panels: Sequence[GoalPanel], title: str) -> Figure:
    """AE per current position, one heat map per method on one shared colour scale."""
    fig, axes = _grid_figure(len(panels), panels[0].field.grid)
    top = shared_ae_scale(panels)
    mesh = None
    for k, (ax, panel) in enumerate(zip(axes, panels, strict=True)):
        grid = panel.field.grid
        x, y = _cell_edges(grid)
        values = np.ma.masked_invalid(panel.ae_deg.T)
        mesh = ax.pcolormesh(x, y, values, cmap=AE_CMAP, vmin=0.0, vmax=top)
        ax.set_facecolor("white")
        xy = grid.position(*np.indices(grid.shape))
        for cx, cy in xy[panel.no_estimate]:
            s = grid.spacing
            ax.add_patch(Rectangle((cx - s / 2, cy - s / 2), s, s, facecolor=MISSING_COLOUR,
                                   hatch="xx", edgecolor=FAILED_COLOUR, linewidth=0))  # fmt: skip
        gx, gy = _goal_xy(panel)
        ax.scatter([gx], [gy], marker="*", s=220, color=GOAL_COLOUR, edgecolor="black", zorder=5)
        _frame_axes(ax, grid, *outer_panel(k, len(panels)))
        ax.set_title(_panel_title(panel, f"mean AE {panel.mean_ae_deg:.1f} deg"))
    fig.colorbar(mesh, ax=axes, label="AE [deg] (one scale for all panels)", shrink=0.8)
    handles = [
        Line2D([], [], marker="*", ls="", color=GOAL_COLOUR, markersize=10, label="goal"),
        Patch(facecolor=MISSING_COLOUR, hatch="xx", edgecolor=FAILED_COLOUR, label="no estimate"),
        Patch(facecolor="white", edgecolor="#888888", label="not tested"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)
    set_title(fig, title)
    return fig
