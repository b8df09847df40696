"""Route homing figures (seed 000): trajectories, and final error against route length.

They take plain arrays (:class:`RouteResult`), whatever produced them. Poses are rows
``(x [m], y [m], heading [rad])`` in the world frame; home is the route's first pose.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from numpy.typing import ArrayLike, NDArray

from homebench.geometry import FloatArray
from homebench.report.style import (
    FAILED_COLOUR,
    GOAL_COLOUR,
    OUTBOUND_COLOUR,
    PLOT_SIZE,
    MethodStyle,
    legend_right,
    new_figure,
    outer_panel,
    panel_axes,
    set_title,
)

#: Final errors below this are drawn at it on the log axis (metres).
ERROR_FLOOR_M = 1e-3


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
    """

    label: str
    outbound: FloatArray
    homing: FloatArray
    intermediate: NDArray[np.int64]
    odometry: FloatArray

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
    ax.scatter(*result.homing[-1, :2], marker="o", s=30, color=style.colour, zorder=5)
    ax.scatter(*result.odometry[-1, :2], marker="x", s=40, color=FAILED_COLOUR, zorder=5)
    ax.scatter(*home, marker="*", s=160, color=GOAL_COLOUR, edgecolor="white", zorder=6)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_title(
        f"{result.label}\nroute {result.route_length_m:.2f} m, final error "
        f"{100 * result.final_error_m:.1f} cm (odometry {100 * result.odometry_error_m:.1f} cm)"
    )


def route_figure(
    results: Sequence[RouteResult], styles: dict[str, MethodStyle], title: str
) -> Figure:
    """Trajectories of route-homing trials side by side, one panel per result."""
    fig = new_figure()
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
               label="intermediate position"),
        Line2D([], [], color=FAILED_COLOUR, linestyle="--", marker="x",
               label="odometry baseline (x: its end)"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)
    set_title(fig, title)
    return fig


def route_error_figure(
    results: Sequence[RouteResult], styles: dict[str, MethodStyle], title: str
) -> Figure:
    """Final position error against route length, per method, beside the odometry baseline."""
    fig = new_figure(PLOT_SIZE)
    ax = fig.add_subplot()
    odometry = sorted({(r.route_length_m, r.odometry_error_m) for r in results})
    length, error = np.array(odometry).T
    ax.plot(length, np.maximum(error, ERROR_FLOOR_M), color=FAILED_COLOUR, linestyle="--",
            marker="x", label="odometry")  # fmt: skip
    for label in sorted({r.label for r in results}):
        mine = sorted((r.route_length_m, r.final_error_m) for r in results if r.label == label)
        length, error = np.array(mine).T
        style = styles[label]
        ax.plot(length, np.maximum(error, ERROR_FLOOR_M), color=style.colour,
                marker=style.marker, linestyle=style.linestyle, label=label)  # fmt: skip
    ax.set_yscale("log")
    ax.set_xlabel("route length [m]")
    ax.set_ylabel(f"final position error [m] (log; below {1000 * ERROR_FLOOR_M:g} mm drawn at it)")
    ax.grid(True, which="both", alpha=0.3)
    legend_right(ax)
    set_title(fig, title)
    return fig
