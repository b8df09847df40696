"""Closed-loop homing figures: trajectories and catchment maps over the floor plan, success
against start distance.

They take plain data: a :class:`~homebench.experiments.closed_loop.floor.FloorPlan`, the
trials table (one row per trial, the columns of ``tables/trials.csv``) and trajectories as
(n, 3) pose arrays (x [m], y [m], heading [rad]), world frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon, Rectangle

from homebench.experiments.closed_loop.floor import FloorPlan
from homebench.experiments.closed_loop.loop import OUTCOMES
from homebench.experiments.closed_loop.tables import catchment_area, catchment_map
from homebench.geometry import FloatArray
from homebench.report.style import (
    DOUBLE_COLUMN,
    GOAL_COLOUR,
    MAX_COLUMNS,
    MethodStyle,
    legend_below,
    legend_right,
    new_figure,
    outer_panel,
    panel_axes,
)

#: Inches: height of a row of floor-plan panels, and of the success figure.
PLAN_ROW_HEIGHT = 2.9
SUCCESS_FIGURE_HEIGHT = 3.4
#: Colour of each trial outcome (trajectories, catchment cells).
OUTCOME_COLOURS = {
    "success": "#4DAF4A",
    "budget": "#FF7F00",
    "steps": "#984EA3",
    "no_estimate": "#999999",
    "collision": "#222222",
    "outside": "#A65628",
}
OBSTACLE_COLOUR = "#9E9E9E"
FAILURE_COLOUR = "#E7298A"
#: Start distances are binned this wide (metres) in the success figure.
DISTANCE_BIN_M = 0.3


def draw_plan(ax: Axes, plan: FloorPlan) -> None:
    """The room's outline and the objects' footprints (filled: obstacles at camera height,
    outlined: objects above or below it)."""
    x0, y0, x1, y1 = plan.bounds
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="black", lw=1.0))
    for outline, obstacle in zip(plan.outlines, plan.obstacles, strict=True):
        ax.add_patch(Polygon(outline, closed=True, lw=0.5, edgecolor=OBSTACLE_COLOUR,
                             facecolor=OBSTACLE_COLOUR if obstacle else "none",
                             alpha=0.7 if obstacle else 1.0))  # fmt: skip
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")


def _goal(ax: Axes, goal: tuple[float, float], radius: float) -> None:
    ax.add_patch(_success_circle(goal, radius))
    ax.scatter(*goal, marker="*", s=110, color=GOAL_COLOUR, edgecolor="white", zorder=6)


def _success_circle(centre: tuple[float, float], radius: float) -> Polygon:
    """The success circle as a polygon (dashed, goal colour)."""
    t = np.linspace(0.0, 2.0 * math.pi, 73)
    ring = np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])
    return Polygon(ring, closed=True, fill=False, edgecolor=GOAL_COLOUR, ls="--", lw=0.8, zorder=5)


def _panels(n: int) -> tuple[Figure, list[Axes]]:
    rows = math.ceil(n / MAX_COLUMNS)
    fig = new_figure((DOUBLE_COLUMN, PLAN_ROW_HEIGHT * rows + 0.8))
    return fig, panel_axes(fig, n)


def _label_axes(axes: Sequence[Axes]) -> None:
    for k, ax in enumerate(axes):
        first_column, bottom = outer_panel(k, len(axes))
        if bottom:
            ax.set_xlabel("x [m]")
        if first_column:
            ax.set_ylabel("y [m]")


def _outcome_handles(shown: Sequence[str]) -> list[Line2D]:
    return [Line2D([], [], color=OUTCOME_COLOURS[o], lw=1.5, label=o.replace("_", " "))
            for o in OUTCOMES if o in shown]  # fmt: skip


def _title(label: str, group: pd.DataFrame) -> str:
    return f"{label}\nsuccess {int(group['success'].sum())}/{len(group)}"


def trajectory_figure(
    plan: FloorPlan,
    trials: pd.DataFrame,
    trajectories: dict[tuple[str, int], FloatArray],
    labels: Sequence[str],
    goal: tuple[float, float],
    success_radius: float,
) -> Figure:
    """One panel per method (``labels`` order): the trajectories of its ``trials`` (one goal),
    ``trajectories[(method, start)]``, coloured by outcome, over the floor plan."""
    fig, axes = _panels(len(labels))
    for ax, label in zip(axes, labels, strict=True):
        draw_plan(ax, plan)
        group = trials[trials["method"] == label]
        for start, outcome in zip(group["start"], group["outcome"], strict=True):
            path = trajectories[(label, int(start))]
            ax.plot(path[:, 0], path[:, 1], color=OUTCOME_COLOURS[outcome], lw=0.6, alpha=0.8)
            ax.plot(*path[0, :2], marker="o", ms=1.5, color=OUTCOME_COLOURS[outcome])
        _goal(ax, goal, success_radius)
        ax.set_title(_title(label, group), fontsize="small")
    _label_axes(axes)
    legend_below(fig, _outcome_handles(list(trials["outcome"].unique())))
    return fig


def _draw_catchment(ax: Axes, group: pd.DataFrame) -> None:
    """Lattice starts: :func:`catchment_map` as cells (green success, red failure); random
    starts: a dot each, coloured the same way."""
    colours = ListedColormap([FAILURE_COLOUR, OUTCOME_COLOURS["success"]])
    if (group["cell_i"] < 0).any():
        ax.scatter(group["start_x"], group["start_y"], s=8, c=group["success"].astype(float),
                   cmap=colours, vmin=0.0, vmax=1.0)  # fmt: skip
        return
    side = math.sqrt(float(group["cell_area_m2"].iloc[0]))
    grid = catchment_map(group)
    x0 = float((group["start_x"] - side * group["cell_i"]).iloc[0]) - side / 2
    y0 = float((group["start_y"] - side * group["cell_j"]).iloc[0]) - side / 2
    extent = (x0, x0 + side * grid.shape[1], y0, y0 + side * grid.shape[0])
    ax.imshow(np.ma.masked_invalid(grid), origin="lower", extent=extent, cmap=colours,
              vmin=0.0, vmax=1.0, alpha=0.8, interpolation="nearest")  # fmt: skip


def catchment_figure(
    plan: FloorPlan,
    trials: pd.DataFrame,
    labels: Sequence[str],
    goal: tuple[float, float],
    success_radius: float,
) -> Figure:
    """One panel per method: the catchment map over the floor plan, each start's cell (a dot
    for random starts) green where homing succeeded, red where it failed."""
    fig, axes = _panels(len(labels))
    for ax, label in zip(axes, labels, strict=True):
        group = trials[trials["method"] == label]
        _draw_catchment(ax, group)
        draw_plan(ax, plan)
        _goal(ax, goal, success_radius)
        area = catchment_area(group["success"], group["cell_area_m2"])
        ax.set_title(f"{label}\ncatchment {area:.2f} m$^2$", fontsize="small")
    _label_axes(axes)
    handles = [Line2D([], [], marker="s", ls="", color=c, label=text) for c, text in
               ((OUTCOME_COLOURS["success"], "success"), (FAILURE_COLOUR, "failure"))]  # fmt: skip
    legend_below(fig, handles)
    return fig


def success_distance_figure(
    trials: pd.DataFrame, labels: Sequence[str], styles: dict[str, MethodStyle]
) -> Figure:
    """Success rate against start distance (bins of DISTANCE_BIN_M), one line per method."""
    fig = new_figure((DOUBLE_COLUMN, SUCCESS_FIGURE_HEIGHT))
    ax = fig.add_subplot()
    bins = np.floor(trials["start_distance_m"] / DISTANCE_BIN_M).astype(int)
    for label in labels:
        mine = trials["method"] == label
        rate = trials[mine].groupby(bins[mine])["success"].mean()
        centre = (rate.index.to_numpy() + 0.5) * DISTANCE_BIN_M
        s = styles[label]
        ax.plot(centre, rate.to_numpy(dtype=float), color=s.colour, marker=s.marker,
                linestyle=s.linestyle, label=label)  # fmt: skip
    ax.set_xlabel(f"start distance [m] (bins of {DISTANCE_BIN_M:g} m)")
    ax.set_ylabel("success rate")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(left=0.0)
    ax.grid(True, alpha=0.3)
    legend_right(ax)
    return fig
