"""Route homing figures (seed 000): trajectories, and final error against route length.

They take plain arrays (:class:`RouteResult`), whatever produced them. Poses are rows
``(x [m], y [m], heading [rad])`` in the world frame; home is the route's first pose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, NullFormatter
from numpy.typing import ArrayLike, NDArray

from homebench.geometry import FloatArray
from homebench.report.style import (
    DOUBLE_COLUMN,
    FAILED_COLOUR,
    GOAL_COLOUR,
    MAX_COLUMNS,
    OUTBOUND_COLOUR,
    MethodStyle,
    legend_right,
    new_figure,
    outer_panel,
    panel_axes,
)

#: Inches: height of a row of trajectory panels, and of the error figure.
ROUTE_ROW_HEIGHT = 3.0
ERROR_FIGURE_HEIGHT = 3.6

#: Final errors below this are drawn at it on the log axis (metres).
ERROR_FLOOR_M = 1e-3
#: The error figure labels its minor ticks when its error axis spans less than this ratio.
MINOR_LABEL_RANGE = 20.0


def _poses(name: str, value: ArrayLike) -> FloatArray:
    poses = np.array(value, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != 3 or len(poses) < 1:
        raise ValueError(f"{name} must have shape (n, 3) with n >= 1, got {poses.shape}")
    poses.setflags(write=False)
    return poses


@dataclass(frozen=True, eq=False)
class RouteResult:
    """One route-homing trial of one method.

    ``outbound`` (n, 3): the route from home (row 0) to where homing starts. ``homing``
    (m, 3): the homing run, from the route's end towards home. ``intermediate`` (k,): indices
    into ``outbound`` of the intermediate positions the method homed through, in the order
    visited. ``odometry`` (p, 3): the baseline, the return driven by odometry alone.
    ``label``: the method; ``trial``: the trial's name (panel titles, default: the label);
    ``planned_length_m``: the length the trial was to drive, shared by its repeats (the error
    figure averages over trials of one planned length; default: each trial on its own).
    """

    label: str
    outbound: FloatArray
    homing: FloatArray
    intermediate: NDArray[np.int64]
    odometry: FloatArray
    trial: str = ""
    planned_length_m: float | None = None

    def __post_init__(self) -> None:
        for name in ("outbound", "homing", "odometry"):
            object.__setattr__(self, name, _poses(name, getattr(self, name)))
        index = np.array(self.intermediate, dtype=np.int64).reshape(-1)
        if np.any((index < 0) | (index >= len(self.outbound))):
            raise ValueError(f"intermediate indices must lie in [0, {len(self.outbound)})")
        index.setflags(write=False)
        object.__setattr__(self, "intermediate", index)

    @property
    def home_xy(self) -> FloatArray:
        return self.outbound[0, :2]

    @property
    def route_length_m(self) -> float:
        """Length of the outbound route in metres."""
        return float(np.sum(np.hypot(*np.diff(self.outbound[:, :2], axis=0).T)))

    @property
    def final_error_m(self) -> float:
        """Distance from the homing run's last position to home, metres."""
        return float(np.hypot(*(self.homing[-1, :2] - self.home_xy)))

    @property
    def odometry_error_m(self) -> float:
        """Distance from the odometry baseline's last position to home, metres."""
        return float(np.hypot(*(self.odometry[-1, :2] - self.home_xy)))


def _draw_route(ax: Axes, result: RouteResult, style: MethodStyle) -> None:
    out, home = result.outbound, result.home_xy
    ax.plot(out[:, 0], out[:, 1], color=OUTBOUND_COLOUR, linewidth=4.0, alpha=0.45, zorder=1)
    step = max(1, len(out) // 8)  # a few arrows show the outbound direction
    for a, b in zip(out[:-1:step], out[1::step], strict=False):
        ax.annotate("", xy=b[:2], xytext=a[:2], zorder=1,
                    arrowprops={"arrowstyle": "->", "color": OUTBOUND_COLOUR})  # fmt: skip
    ax.plot(result.odometry[:, 0], result.odometry[:, 1], color=FAILED_COLOUR, linestyle="--",
            linewidth=1.0, zorder=2)  # fmt: skip
    ax.plot(result.homing[:, 0], result.homing[:, 1], color=style.colour, linewidth=1.5, zorder=3)
    mid = out[result.intermediate]
    ax.scatter(mid[:, 0], mid[:, 1], marker="s", s=28, facecolor="white",
               edgecolor=style.colour, linewidth=1.5, zorder=4)  # fmt: skip
    for k, xy in enumerate(mid[:, :2], start=1):  # the order homing visits them
        ax.annotate(str(k), xy, xytext=(5, 4), textcoords="offset points", fontsize=7,
                    color=style.colour, zorder=4)  # fmt: skip
    ax.scatter(*result.homing[-1, :2], marker="o", s=30, color=style.colour, zorder=5)
    ax.scatter(*result.odometry[-1, :2], marker="x", s=40, color=FAILED_COLOUR, zorder=5)
    ax.scatter(*home, marker="*", s=160, color=GOAL_COLOUR, edgecolor="white", zorder=6)
    ax.grid(True, alpha=0.3)
    ax.set_title(  # three short lines: four panels share a double column
        f"{result.trial or result.label}\n{result.route_length_m:.2f} m route: "
        f"{100 * result.final_error_m:.1f} cm\nodometry: {100 * result.odometry_error_m:.1f} cm",
        fontsize="small",
    )


def _equal_scales(fig: Figure, axes: Sequence[Axes]) -> None:
    """Equal x and y scales on ``axes`` (sharing both), the limits widened in x or y so the
    data's shape matches the panels' laid out shape.

    Equal scales alone would leave a narrow route (a straight line) a thin strip in a wide
    panel, or a wide one a band in a tall panel.
    """
    fig.draw_without_rendering()  # lays the panels out at their full size
    ax = axes[0]
    box = ax.get_position()
    shape = (box.width * fig.get_figwidth()) / (box.height * fig.get_figheight())
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    if x1 - x0 < shape * (y1 - y0):
        half = 0.5 * shape * (y1 - y0)
        ax.set_xlim(0.5 * (x0 + x1) - half, 0.5 * (x0 + x1) + half)
    else:
        half = 0.5 * (x1 - x0) / shape
        ax.set_ylim(0.5 * (y0 + y1) - half, 0.5 * (y0 + y1) + half)
    for ax in axes:
        ax.set_aspect("equal")


def route_figure(results: Sequence[RouteResult], styles: dict[str, MethodStyle]) -> Figure:
    """Trajectories of route-homing trials side by side, one panel per result (shared axes,
    equal scales), double-column wide; the report's caption says what they show."""
    rows = math.ceil(len(results) / MAX_COLUMNS)
    fig = new_figure((DOUBLE_COLUMN, ROUTE_ROW_HEIGHT * rows + 0.9))
    axes = panel_axes(fig, len(results))
    for k, (ax, result) in enumerate(zip(axes, results, strict=True)):
        _draw_route(ax, result, styles[result.label])
        first_column, bottom = outer_panel(k, len(results))
        if bottom:
            ax.set_xlabel("x [m]")
        if first_column:
            ax.set_ylabel("y [m]")
    handles = [
        Line2D([], [], marker="*", ls="", color=GOAL_COLOUR, markersize=11, label="home"),
        Line2D([], [], color=OUTBOUND_COLOUR, linewidth=4.0, alpha=0.45, label="outbound route"),
        Line2D([], [], color="#555555", linewidth=1.5, label="homing (method colour)"),
        Line2D([], [], marker="s", ls="", markerfacecolor="white", markeredgecolor="#555555",
               label="intermediate position (visiting order)"),
        Line2D([], [], color=FAILED_COLOUR, linestyle="--", marker="x",
               label="odometry baseline (x: its end)"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncols=3, frameon=False)
    _equal_scales(fig, axes)
    return fig


def _mean_by_length(points: Sequence[tuple[float, float, float]]) -> FloatArray:
    """(k, 2) mean (route length, error) per planned length of ``points`` (planned length,
    route length, error), by planned length."""
    planned = sorted({p for p, _, _ in points})
    return np.array([np.mean([(x, y) for p, x, y in points if p == q], axis=0) for q in planned])


def _plot_errors(
    ax: Axes, points: Sequence[tuple[float, float, float]], label: str, style: MethodStyle
) -> None:
    """Each trial as a hollow marker, the mean per planned length as a line of filled ones."""
    _, length, error = np.array(points).T
    ax.plot(length, np.maximum(error, ERROR_FLOOR_M), linestyle="none", marker=style.marker,
            markerfacecolor="none", color=style.colour, alpha=0.7)  # fmt: skip
    mean = _mean_by_length(points)
    ax.plot(mean[:, 0], np.maximum(mean[:, 1], ERROR_FLOOR_M), color=style.colour,
            linestyle=style.linestyle, marker=style.marker, markersize=5, label=label)  # fmt: skip


def _planned(result: RouteResult) -> float:
    if result.planned_length_m is None:
        return result.route_length_m
    return result.planned_length_m


def route_error_figure(results: Sequence[RouteResult], styles: dict[str, MethodStyle]) -> Figure:
    """Final position error against route length, per method, beside the odometry baseline.

    Hollow markers: trials; lines through filled markers: the mean over the trials of each
    planned length. Log error axis, linear length axis from zero. Double-column wide; the
    report's caption says what it shows.
    """
    fig = new_figure((DOUBLE_COLUMN, ERROR_FIGURE_HEIGHT))
    ax = fig.add_subplot()
    odometry = sorted({(_planned(r), r.route_length_m, r.odometry_error_m) for r in results})
    _plot_errors(ax, odometry, "odometry", MethodStyle(FAILED_COLOUR, "x", "--"))
    for label in sorted({r.label for r in results}):
        mine = [
            (_planned(r), r.route_length_m, r.final_error_m) for r in results if r.label == label
        ]
        _plot_errors(ax, mine, label, styles[label])
    ax.set_yscale("log")
    plain = FuncFormatter(lambda value, _: f"{value:g}")  # 0.05, not 5 x 10^-2
    ax.yaxis.set_major_formatter(plain)
    low, high = ax.get_ylim()
    if high / low < 10.0:  # at least the decade(s) around the data
        low, high = 10.0 ** math.floor(math.log10(low)), 10.0 ** math.ceil(math.log10(high))
        ax.set_ylim(low, high)
    # minor ticks labelled only when few decades show
    ax.yaxis.set_minor_formatter(plain if high / low < MINOR_LABEL_RANGE else NullFormatter())
    ax.set_xlim(left=0.0)
    ax.set_xlabel("route length [m]")
    ax.set_ylabel(f"final position error [m] (log; below {1000 * ERROR_FLOOR_M:g} mm drawn at it)")
    ax.grid(True, which="both", alpha=0.3)
    legend_right(ax, "mean per length\n(hollow: trials)")
    return fig
