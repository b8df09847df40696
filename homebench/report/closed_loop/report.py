"""The report of a closed-loop homing run (``kind: closed-loop``): tables, figures, title page.

A closed-loop run's folder holds ``config.resolved.json`` (a :class:`ClosedLoopConfig`), which
says what trials there should be, and ``trials/.../*.json`` per finished trial
(:mod:`homebench.experiments.closed_loop.experiment`). A trial file that is missing, corrupt or
of another configuration becomes a warning line, as a grid run's job files do. The tables are
:mod:`homebench.experiments.closed_loop.tables`' (the run's own CSVs, rebuilt from the trials).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from pydantic import BaseModel, ValidationError

from homebench.errors import DataError
from homebench.experiments.closed_loop.config import (
    DATABASE_STYLE,
    ClosedLoopConfig,
    ResolvedClosedLoopConfig,
)
from homebench.experiments.closed_loop.experiment import (
    ClosedLoopJob,
    plan_trials,
    styles,
    trial_scene,
)
from homebench.experiments.closed_loop.floor import FloorPlan, grid_plan, world_plan
from homebench.experiments.closed_loop.tables import (
    catchment_table,
    paired_table,
    summary_table,
    trials_frame,
)
from homebench.experiments.closed_loop.views import lattice_error
from homebench.geometry import FloatArray
from homebench.report.closed_loop.figures import (
    catchment_figure,
    success_distance_figure,
    trajectory_figure,
)
from homebench.report.pages import environment_lines, run_lines
from homebench.report.run_data import CONFIG_FILE, RunInfo, validation_error
from homebench.report.style import method_styles
from homebench.report.tables import (
    FIXED0,
    FIXED2,
    FIXED3,
    P_VALUE,
    SIGNIFICANT3,
    Columns,
    TableView,
    make_view,
    scaled_columns,
)

#: Summary columns: source -> (header with unit, digits, scale); None digits: text.
SUMMARY_COLUMNS: Columns = {
    "style": ("style", None, 1.0),
    "method": ("method", None, 1.0),
    "trials": ("trials", FIXED0, 1.0),
    "success": ("success rate", FIXED2, 1.0),
    "success_lo": ("success_lo", FIXED2, 1.0),
    "success_hi": ("success_hi", FIXED2, 1.0),
    "catchment_m2": ("catchment [m^2]", FIXED2, 1.0),
    "final_distance_m": ("final distance, median [cm]", FIXED2, 100.0),
    "path_ratio": ("path ratio (successes)", FIXED2, 1.0),
    "steps": ("steps", FIXED2, 1.0),
    "no_estimate_share": ("steps without estimate", FIXED3, 1.0),
    "collisions": ("collisions", FIXED0, 1.0),
    "outside": ("left the grid", FIXED0, 1.0),
    "s_per_step": ("time per step [ms]", SIGNIFICANT3, 1000.0),
}
CATCHMENT_COLUMNS: Columns = {
    "style": ("style", None, 1.0),
    "method": ("method", None, 1.0),
    "goal": ("goal", FIXED0, 1.0),
    "starts": ("starts", FIXED0, 1.0),
    "successes": ("successes", FIXED0, 1.0),
    "catchment_m2": ("catchment [m^2]", FIXED2, 1.0),
    "covered_m2": ("floor the starts cover [m^2]", FIXED2, 1.0),
}
PAIRED_COLUMNS: Columns = {
    "style": ("style", None, 1.0),
    "method_a": ("method A", None, 1.0),
    "method_b": ("method B", None, 1.0),
    "starts": ("starts", FIXED0, 1.0),
    "only_a": ("A only", FIXED0, 1.0),
    "only_b": ("B only", FIXED0, 1.0),
    "p": ("p (McNemar exact)", P_VALUE, 1.0),
    "p_holm": ("p (Holm)", P_VALUE, 1.0),
}


@dataclass(frozen=True)
class ClosedLoopRun:
    """A closed-loop run as the report sees it: the config, the finished trials' table (plan
    order) and trajectories by (style, method, goal, start), and one warning line per planned
    trial without a valid file."""

    info: RunInfo
    config: ClosedLoopConfig
    trials: pd.DataFrame
    trajectories: dict[tuple[str, str, int, int], FloatArray]
    planned: int
    warnings: list[str]


def load_closed_loop_run(info: RunInfo) -> ClosedLoopRun:
    """The trials of the closed-loop run ``info``; DataError when its config is invalid or no
    trial has a valid file."""
    try:
        config = ResolvedClosedLoopConfig.model_validate(info.config)
    except ValidationError as error:
        raise validation_error(info.run_dir / CONFIG_FILE, "", error) from None
    records, warnings = [], []
    plan = plan_trials(config)
    for trial in plan:
        loaded = ClosedLoopJob(config, trial).read(info.run_dir)
        (warnings if isinstance(loaded, str) else records).append(loaded)
    if not records:
        shown = "; ".join(warnings[:3]) + (" ..." if len(warnings) > 3 else "")
        raise DataError(f"{info.run_dir}: no trial results to report on (missing: {shown})")
    trajectories = {
        (s["style"], s["method"], int(s["goal"]), int(s["start"])): np.asarray(
            r["trajectory"], dtype=np.float64
        )
        for r in records
        for s in [r["summary"]]
    }
    return ClosedLoopRun(
        info, config, trials_frame(records, config), trajectories, len(plan), warnings
    )


# --------------------------------------------------------------------------- title page


def _params(model: BaseModel) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in sorted(model.model_dump(mode="json").items()))


def _scene_line(c: ClosedLoopConfig) -> str:
    if c.database is not None:
        return f"grid database {c.database}: the robot sees the nearest grid image"
    return (
        f"worlds: generated, style(s) {', '.join(styles(c))}, variant {c.world.variant} (seed "
        f"{c.world.seed}), panoramas {c.world.unfolded.width} px wide"
    )


def _render_line(c: ClosedLoopConfig) -> str:
    if c.database is not None or c.render.lattice is None:
        return "views: rendered at each pose as it is"
    position, heading = lattice_error(c.render.lattice, c.world.unfolded.width)
    return (
        f"views: rendered at heading 0 on a {100 * c.render.lattice:g} cm lattice and turned by "
        f"whole columns (the view's pose is off the true one by at most {100 * position:.1f} "
        f"cm and {math.degrees(heading):.2f} deg)"
    )


def _results_lines(run: ClosedLoopRun) -> list[str]:
    missing = len(run.warnings)
    summary = summary_table(run.trials, run.config.seed)
    best = summary.sort_values("success", ascending=False, kind="stable").iloc[0]
    return [
        f"{len(run.trials)} of {run.planned} planned trials; missing or corrupt trial files: "
        f"{missing}{' (see the next page)' if missing else ''}",
        f"highest success rate: {best['method']} ({best['style']}), {best['success']:.2f}",
    ]


def closed_loop_summary(run: ClosedLoopRun) -> dict[str, list[str]]:
    """A closed-loop run's title page sections: heading -> lines."""
    c = run.config
    return {
        "Run": run_lines(run.info),
        "Experiment": [
            "closed-loop homing: from each start the robot sees its view, asks the method for "
            "the home direction, turns (limited) and steps, until it is within the success "
            "radius, past the path budget or out of free space; controls: truth (the true "
            "direction) and random",
            _scene_line(c),
            f"methods: {', '.join(c.labels())}",
            f"goals: {len(c.goals)}; starts: {_params(c.starts)}, frame {c.frame}",
            f"motion: {_params(c.motion)}",
            f"drift: {_params(c.drift)}",
            _render_line(c),
            f"seed: {c.seed}",
        ],
        "Results": _results_lines(run),
        "Environment": environment_lines(run.info),
    }


# --------------------------------------------------------------------------- tables


def _view(name: str, title: str, frame: pd.DataFrame, columns: Columns, **kwargs: Any) -> TableView:
    out, digits = scaled_columns(frame, columns)
    return make_view(name, title, out, digits, **kwargs)


def summary_view(summary: pd.DataFrame) -> TableView:
    """The per-method summary (:func:`summary_table`): success rate [95 % interval],
    catchment, final distance, path ratio, steps, collisions, time: the report's first table
    and, narrowed, what ``homebench run`` prints (:mod:`homebench.report.consoles`)."""
    return _view(
        "summary", "Closed-loop homing per method: success rate [95 % interval], catchment area",
        summary, SUMMARY_COLUMNS, bounds={"success rate": ("success_lo", "success_hi")},
        notes=("interval: bootstrap over starts (over goals when there are several)",),
    )  # fmt: skip


def closed_loop_views(run: ClosedLoopRun) -> list[TableView]:
    """The report tables: summary, catchment per goal, paired tests, then every trial."""
    frame, seed = run.trials, run.config.seed
    summary = summary_view(summary_table(frame, seed))
    catchment = _view("catchment", "Catchment area per goal (cells x cell area)",
                      catchment_table(frame), CATCHMENT_COLUMNS)  # fmt: skip
    paired = _view("paired", "Paired comparison on success from the same starts",
                   paired_table(frame), PAIRED_COLUMNS)  # fmt: skip
    shown = frame.drop(columns=["success"]).assign(success=frame["success"].astype(int))
    trials = make_view("trials", "Every trial (per-start outcomes)", shown, {})
    return [summary, catchment, paired, trials]


# --------------------------------------------------------------------------- figures


def _plan(config: ClosedLoopConfig, style: str) -> FloorPlan:
    if style == DATABASE_STYLE:
        grid = trial_scene(config, style).grid
        assert grid is not None
        return grid_plan(grid)
    world = next(w for w in config.worlds() if w is not None and w.style == style)
    return world_plan(world)


def closed_loop_figures(run: ClosedLoopRun) -> Iterator[tuple[str, str, str, Figure]]:
    """(file stem, section, caption, figure): per style, success against start distance, then
    per goal the catchment maps and the trajectories."""
    c = run.config
    labels = [label for label in c.labels() if label in set(run.trials["method"])]
    colours = method_styles(labels)
    radius = c.motion.success_radius
    for style, frame in run.trials.groupby("style", sort=False):
        yield (f"success_distance_{style}", "Success", f"Success rate against start distance, "
               f"{style}", success_distance_figure(frame, labels, colours))  # fmt: skip
        plan = _plan(c, str(style))
        for goal, trials in frame.groupby("goal"):
            where = f"{style}, goal {goal}"
            at = (float(trials["goal_x"].iloc[0]), float(trials["goal_y"].iloc[0]))
            caption = (
                f"Catchment maps, {where}: each start's cell green where homing succeeded, red "
                "where it failed, over the floor plan (grey: objects at camera height)"
            )
            figure = catchment_figure(plan, trials, labels, at, radius)
            yield f"catchment_{style}_g{goal}", "Catchment", caption, figure
            paths = {
                (m, s): run.trajectories[(str(style), m, int(goal), s)]
                for m, s in zip(trials["method"], trials["start"].astype(int), strict=True)
            }
            yield (f"trajectories_{style}_g{goal}", "Trajectories", f"Trajectories, {where}, "
                   "coloured by outcome (star: goal, dashed: success radius)",
                   trajectory_figure(plan, trials, paths, labels, at, radius))  # fmt: skip
