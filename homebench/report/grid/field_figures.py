"""Figures on the capture grid, one panel per method and goal: home-vector fields (seed 001,
Figure 7) and AE maps (Figure 8). Axes are world metres, x to the right, y up.

A figure holds the panels of up to :data:`MAX_GOALS_PER_FIGURE` goals, a goal's methods side by
side; :func:`grid_layout` says how many fit a journal page for a grid, so every goal of a run
can be drawn on as many figures as it takes. AE maps share one fixed scale, 0 to
:data:`AE_MAX_DEG` degrees like the paper's; larger errors take the top colour.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.textpath import TextPath
from matplotlib.ticker import MaxNLocator

from homebench.geometry import Grid
from homebench.report.grid.figure_data import Goal, GoalPanel, pages
from homebench.report.style import (
    DOUBLE_COLUMN,
    FAILED_COLOUR,
    GOAL_COLOUR,
    MAX_COLUMNS,
    MAX_FIGURE_HEIGHT,
    MISSING_COLOUR,
    RC_PARAMS,
    SINGLE_COLUMN,
    MethodStyle,
    legend_below,
    new_figure,
)

#: Goals drawn on one figure, at most.
MAX_GOALS_PER_FIGURE = 4
#: Inches beside the panels (axis labels, colour bar) and below them (legend, x label).
GRID_SIDE_MARGIN = 1.0
GRID_BOTTOM_MARGIN = 0.9
#: Widest panel, inches (few methods: more goals per figure instead of larger panels).
MAX_PANEL_WIDTH = 2.4
#: Inches above each panel for its title (two lines, :func:`panel_title`).
PANEL_TITLE_HEIGHT = 0.36
#: A panel title's font may shrink to this size (points) to fit its panel, no further.
TITLE_MIN_POINTS = 6.0
TITLE_POINTS_STEP = 0.5
#: Arrow length as a share of the grid spacing: from a position's centre, it stays in its
#: cell, so no arrow leaves the axes (limits half a spacing beyond the grid).
ARROW_LENGTH = 0.45
#: AE colour map (dark = small error) and its fixed range, degrees.
AE_CMAP = "viridis"
AE_MAX_DEG = 100.0

GoalPanels = tuple[Goal, Sequence[GoalPanel]]


@dataclass(frozen=True)
class GridLayout:
    """Panels of a grid figure: ``columns`` methods per row, ``rows_per_goal`` rows a goal,
    panels ``panel_width`` inches wide (plus the title, ``panel_height`` tall), at most
    ``goals_per_figure`` goals on a figure ``width`` inches wide."""

    columns: int
    rows_per_goal: int
    panel_width: float
    panel_height: float
    goals_per_figure: int
    width: float

    def size(self, n_goals: int) -> tuple[float, float]:
        """Width and height (inches) of a figure of ``n_goals`` goals."""
        rows = n_goals * self.rows_per_goal
        return self.width, rows * self.panel_height + GRID_BOTTOM_MARGIN


def grid_layout(grid: Grid, n_methods: int) -> GridLayout:
    """The layout of the field and AE figures of ``n_methods`` methods on ``grid``: one column
    wide for a single method, else two; as many goals as fit MAX_FIGURE_HEIGHT (at least one,
    panels shrunk if need be, at most MAX_GOALS_PER_FIGURE)."""
    columns = min(n_methods, MAX_COLUMNS)
    rows_per_goal = math.ceil(n_methods / columns)
    width = SINGLE_COLUMN if columns == 1 else DOUBLE_COLUMN
    aspect = grid.shape[1] / grid.shape[0]
    room = MAX_FIGURE_HEIGHT - GRID_BOTTOM_MARGIN
    panel_width = min(
        MAX_PANEL_WIDTH,
        (width - GRID_SIDE_MARGIN) / columns,
        (room / rows_per_goal - PANEL_TITLE_HEIGHT) / aspect,
    )
    panel_height = panel_width * aspect + PANEL_TITLE_HEIGHT
    fits = math.floor(room / (rows_per_goal * panel_height) + 1e-9)
    goals = max(1, min(MAX_GOALS_PER_FIGURE, fits))
    return GridLayout(columns, rows_per_goal, panel_width, panel_height, goals, width)


def grid_pages(goals: Sequence[GoalPanels]) -> list[list[GoalPanels]]:
    """``goals`` cut into the field / AE figures' pages: :func:`grid_layout`'s goals per
    figure each (none for no goal)."""
    if not goals:
        return []
    n_methods = max(len(panels) for _, panels in goals)
    per_figure = grid_layout(goals[0][1][0].field.grid, n_methods).goals_per_figure
    return pages(goals, per_figure)


def _grid_axes(goals: Sequence[GoalPanels]) -> tuple[Figure, list[list[Axes]], GridLayout]:
    """A figure with one axes per method and goal (``axes[goal][method]``); unused slots of a
    goal's last row are hidden, tick labels only on the outer panels."""
    n_methods = max(len(panels) for _, panels in goals)
    layout = grid_layout(goals[0][1][0].field.grid, n_methods)
    fig = new_figure(layout.size(len(goals)))
    rows = len(goals) * layout.rows_per_goal
    grid_axes = fig.subplots(rows, layout.columns, squeeze=False)
    axes: list[list[Axes]] = []
    for g, (_, panels) in enumerate(goals):
        block = grid_axes[g * layout.rows_per_goal : (g + 1) * layout.rows_per_goal].ravel()
        for ax in block[len(panels) :]:
            ax.set_visible(False)
        axes.append(list(block[: len(panels)]))
    _label_outer(grid_axes, [ax for row in axes for ax in row])
    return fig, axes, layout


def _label_outer(grid_axes: np.ndarray, shown: list[Axes]) -> None:
    """Axis labels and tick labels on the first column and the lowest shown panel of each
    column only."""
    for column in range(grid_axes.shape[1]):
        visible = [ax for ax in grid_axes[:, column] if ax in shown]
        for ax in visible:
            bottom = ax is visible[-1]
            ax.tick_params(labelbottom=bottom, labelleft=column == 0)
            ax.set_xlabel("x [m]" if bottom else "")
            ax.set_ylabel("y [m]" if column == 0 else "")


def _frame_axes(ax: Axes, grid: Grid) -> None:
    """Limits half a spacing beyond the grid, equal aspect."""
    (x0, y0), (x1, y1) = grid.position(0, 0), grid.position(grid.shape[0] - 1, grid.shape[1] - 1)
    half = grid.spacing / 2
    ax.set_xlim(x0 - half, x1 + half)
    ax.set_ylim(y0 - half, y1 + half)
    ax.set_aspect("equal")
    # no tick on the edges: neighbouring panels' edge labels would run into each other
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MaxNLocator(nbins=4, prune="both"))


def text_width(text: str, points: float) -> float:
    """Width (inches) of ``text`` set in the default font at ``points`` points, measured on
    its glyphs' outlines (no renderer needed)."""
    if not text:
        return 0.0
    path = TextPath((0.0, 0.0), text, size=points, prop=FontProperties())
    return float(path.get_extents().width) / 72.0


def _wrap_measured(line: str, width: float, points: float) -> list[str]:
    """``line`` broken at spaces into lines each at most ``width`` inches wide at ``points``
    (a single word wider than that keeps a line of its own)."""
    lines: list[str] = []
    for word in line.split(" "):
        joined = f"{lines[-1]} {word}" if lines else word
        if lines and text_width(joined, points) <= width:
            lines[-1] = joined
        else:
            lines.append(word)
    return lines


@dataclass(frozen=True)
class PanelTitle:
    """A per-goal panel's title: its ``text`` (lines joined by newlines) and font size
    (``points``)."""

    text: str
    points: float


def panel_title(
    label: str,
    goal: str,
    detail: str,
    width: float,
    points: float = RC_PARAMS["axes.titlesize"],
) -> PanelTitle:
    """Two lines, "<label>, goal <goal>" and ``detail``, fitted to ``width`` inches: the font
    shrinks from ``points`` in steps of TITLE_POINTS_STEP, not below TITLE_MIN_POINTS, until
    both lines' measured widths fit; a line that still does not fit wraps at its measured
    width."""
    lines = [f"{label}, goal {goal}", detail]
    while points > TITLE_MIN_POINTS and max(text_width(t, points) for t in lines) > width:
        points = max(TITLE_MIN_POINTS, points - TITLE_POINTS_STEP)
    wrapped = [part for line in lines for part in _wrap_measured(line, width, points)]
    return PanelTitle("\n".join(wrapped), points)


def _panel_title(ax: Axes, goal: Goal, panel: GoalPanel, extra: str, width: float) -> None:
    rr = "RR n/a" if math.isnan(panel.rr) else f"RR {panel.rr:.2f}"
    title = panel_title(panel.label, goal.text, f"{extra}, {rr}", width)
    ax.set_title(title.text, fontsize=title.points)


def _goal_xy(panel: GoalPanel) -> tuple[float, float]:
    x, y = panel.field.goal_xy
    return float(x), float(y)


def _draw_field(ax: Axes, panel: GoalPanel, style: MethodStyle) -> None:
    grid = panel.field.grid
    xy = grid.position(*np.indices(grid.shape))
    angles = panel.field.angles
    has = panel.tested & ~np.isnan(angles)
    length = ARROW_LENGTH * grid.spacing
    tested = xy[panel.tested]
    ax.scatter(tested[:, 0], tested[:, 1], marker="s", s=4, color=MISSING_COLOUR, zorder=1)
    succeeded, failed = has & ~panel.rr_failed, has & panel.rr_failed
    for mask, colour in ((succeeded, style.colour), (failed, FAILED_COLOUR)):
        if not mask.any():
            continue
        u, v = length * np.cos(angles[mask]), length * np.sin(angles[mask])
        ax.quiver(xy[mask][:, 0], xy[mask][:, 1], u, v, color=colour, angles="xy",
                  scale_units="xy", scale=1, width=0.012, headwidth=4, headlength=4.5,
                  headaxislength=4, pivot="tail", zorder=3)  # fmt: skip
    missing = xy[panel.no_estimate]
    ax.scatter(missing[:, 0], missing[:, 1], marker="x", s=12, linewidths=0.8,
               color=FAILED_COLOUR, zorder=4)  # fmt: skip
    gx, gy = _goal_xy(panel)
    ax.scatter([gx], [gy], marker="s", s=30, color=GOAL_COLOUR, edgecolor="black",
               linewidths=0.5, zorder=5, clip_on=False)  # fmt: skip


def field_figure(goals: Sequence[GoalPanels], styles: dict[str, MethodStyle]) -> Figure:
    """Home-vector fields of several methods towards each of ``goals`` (methods side by side,
    a goal's panels below the previous goal's).

    Arrows start at each tested position and point along its estimated home direction (world
    frame), in the method's colour where the return-ratio trial started there succeeds, dark
    where it fails.
    """
    fig, axes, layout = _grid_axes(goals)
    for (goal, panels), row in zip(goals, axes, strict=True):
        for ax, panel in zip(row, panels, strict=True):
            _draw_field(ax, panel, styles[panel.label])
            _frame_axes(ax, panel.field.grid)
            n_missing = int(panel.no_estimate.sum())
            _panel_title(ax, goal, panel, f"{n_missing} no est.", layout.panel_width)
    handles = [
        Line2D([], [], marker="s", ls="", color=GOAL_COLOUR, markersize=5, label="goal"),
        Line2D([], [], marker="s", ls="", color=MISSING_COLOUR, markersize=3,
               label="current position"),
        Line2D([], [], marker=r"$\rightarrow$", ls="", color="#555555", markersize=9,
               label="home vector, RR trial succeeds"),
        Line2D([], [], marker=r"$\rightarrow$", ls="", color=FAILED_COLOUR, markersize=9,
               label="home vector, RR trial fails"),
        Line2D([], [], marker="x", ls="", color=FAILED_COLOUR, markersize=5, label="no estimate"),
    ]  # fmt: skip
    legend_below(fig, handles, 3)
    return fig


def _cell_edges(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    i_edges = np.arange(grid.shape[0] + 1) - 0.5
    j_edges = np.arange(grid.shape[1] + 1) - 0.5
    x = grid.origin[0] + i_edges * grid.spacing
    y = grid.origin[1] + j_edges * grid.spacing
    return x, y


def _draw_ae(ax: Axes, panel: GoalPanel) -> object:
    """The AE map of ``panel`` on the fixed scale; returns the mesh (for the colour bar)."""
    grid = panel.field.grid
    x, y = _cell_edges(grid)
    values = np.ma.masked_invalid(panel.ae_deg.T)
    mesh = ax.pcolormesh(x, y, values, cmap=AE_CMAP, vmin=0.0, vmax=AE_MAX_DEG)
    ax.set_facecolor("white")
    s = grid.spacing
    corners = grid.position(*np.indices(grid.shape))[panel.no_estimate] - s / 2
    cells = [Rectangle((x, y), s, s) for x, y in corners]  # one collection: quick to build
    ax.add_collection(PatchCollection(cells, facecolor=MISSING_COLOUR, hatch="xx",
                                      edgecolor=FAILED_COLOUR, linewidth=0))  # fmt: skip
    gx, gy = _goal_xy(panel)
    ax.scatter([gx], [gy], marker="*", s=60, color=GOAL_COLOUR, edgecolor="black",
               linewidths=0.5, zorder=5, clip_on=False)  # fmt: skip
    return mesh


def ae_figure(goals: Sequence[GoalPanels]) -> Figure:
    """AE per current position, one map per method and goal, all on the scale 0 to
    AE_MAX_DEG degrees (larger errors in the top colour; the colour bar's arrow says so)."""
    fig, axes, layout = _grid_axes(goals)
    mesh = None
    for (goal, panels), row in zip(goals, axes, strict=True):
        for ax, panel in zip(row, panels, strict=True):
            mesh = _draw_ae(ax, panel)
            _frame_axes(ax, panel.field.grid)
            _panel_title(
                ax, goal, panel, f"mean AE {panel.mean_ae_deg:.1f} deg", layout.panel_width
            )
    shown = [ax for row in axes for ax in row]
    fig.colorbar(mesh, ax=shown, extend="max", shrink=0.6,
                 label=f"AE [deg] (above {AE_MAX_DEG:g}: top colour)")  # fmt: skip
    handles = [
        Line2D([], [], marker="*", ls="", color=GOAL_COLOUR, markersize=7, label="goal"),
        Patch(facecolor=MISSING_COLOUR, hatch="xx", edgecolor=FAILED_COLOUR, label="no estimate"),
        Patch(facecolor="white", edgecolor="#888888", label="not tested"),
    ]
    legend_below(fig, handles, 3)
    return fig
