"""The report of a route-homing run (``kind: route``, seed 000): trials, tables, figures.

A route run's folder holds ``config.resolved.json`` (a :class:`RouteConfig`), which says what
trials and methods there should be, and a result file per finished job
(:mod:`homebench.experiments.route.experiment`). A trial file that is missing, corrupt or of
another configuration (its key differs) becomes a warning line, as a grid run's job files do.

A run of one method (klt-sector by default) gets the per-length and per-trial tables, the
final errors and the trajectories. A run of several methods gets the comparison of
:mod:`homebench.report.route.compare` first (per method with intervals over trials, paired
tests, per length), the per-trial table with a method column, and the trajectories of the
first trial of each route and length, one panel per method.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import pandas as pd
from matplotlib.figure import Figure
from pydantic import BaseModel, ValidationError

from homebench.errors import DataError
from homebench.experiments.route.config import (
    KLT_SECTOR,
    ResolvedRouteConfig,
    RouteConfig,
    RouteSpec,
)
from homebench.experiments.route.experiment import RouteJob, RouteTrial, route_jobs
from homebench.experiments.route.probes import ridf_figure
from homebench.report.pages import environment_lines, run_lines
from homebench.report.route.compare import (
    error_interval_figure,
    length_view,
    method_view,
    paired_view,
)
from homebench.report.route.figures import RouteResult, route_error_figure, route_figure
from homebench.report.run_data import CONFIG_FILE, RunInfo, validation_error
from homebench.report.style import MAX_COLUMNS, method_styles
from homebench.report.tables import (
    FIXED0,
    FIXED1,
    FIXED2,
    Columns,
    TableView,
    make_view,
    scaled_columns,
)

#: Trajectory panels per page (one row).
PANELS_PER_PAGE = MAX_COLUMNS
#: The status of a visual homing run that reached home.
REACHED = "reached"
#: Table columns: source column -> (header with unit, digits or None for text, scale).

#: Columns of the per-trial table: summary key -> (header, digits, scale); None: text.
TRIAL_COLUMNS: Columns = {
    "trial": ("trial", None, 1.0),
    "driven_m": ("route length [m]", FIXED2, 1.0),
    "frames": ("frames", FIXED0, 1.0),
    "features": ("features tracked", FIXED0, 1.0),
    "n_intermediate": ("intermediate positions", FIXED0, 1.0),
    "visual_status": ("visual status", None, 1.0),
    "visual_error_m": ("visual error [cm]", FIXED2, 100.0),
    "visual_heading_error_deg": ("visual heading error [deg]", FIXED2, 1.0),
    "odometry_error_m": ("odometry error [cm]", FIXED2, 100.0),
    "odometry_heading_error_deg": ("odometry heading error [deg]", FIXED2, 1.0),
    "odometry_drift_at_end_m": ("odometry drift at route end [cm]", FIXED2, 100.0),
}
#: Columns of the per-length table: aggregate -> (header, digits, scale); None: text.
LENGTH_COLUMNS: Columns = {
    "route": ("route", None, 1.0),
    "length_m": ("length [m]", FIXED2, 1.0),
    "trials": ("trials", FIXED0, 1.0),
    "reached": ("reached home", FIXED0, 1.0),
    "driven_m": ("route length [m]", FIXED2, 1.0),
    "n_intermediate": ("intermediate positions", FIXED1, 1.0),
    "visual_mean": ("visual error mean [cm]", FIXED2, 100.0),
    "visual_max": ("visual error max [cm]", FIXED2, 100.0),
    "odometry_mean": ("odometry error mean [cm]", FIXED2, 100.0),
    "odometry_max": ("odometry error max [cm]", FIXED2, 100.0),
    "visual_heading": ("visual heading error [deg]", FIXED2, 1.0),
    "odometry_heading": ("odometry heading error [deg]", FIXED2, 1.0),
}


@dataclass(frozen=True)
class TrialData:
    """One finished job: its trial, the method's ``label``, its ``summary`` (the table's row),
    its poses and, for a route-learning method probed along its route, the ``probes`` rows
    (:mod:`homebench.experiments.route.probes`, each with its RIDF)."""

    trial: RouteTrial
    label: str
    summary: dict[str, Any]
    result: RouteResult
    probes: list[dict[str, Any]] | None = None


@dataclass(frozen=True)
class RouteRun:
    """A route run as the report sees it: the config, the finished trials in plan order, and
    one warning line per planned trial without a valid file."""

    info: RunInfo
    config: RouteConfig
    trials: list[TrialData]
    planned: int
    warnings: list[str]

    @property
    def labels(self) -> list[str]:
        """The config's method labels, in order."""
        return [label for label, _, _ in self.config.method_points()]

    @property
    def compared(self) -> bool:
        """Whether the run compares several methods."""
        return len(self.labels) > 1


def _trial_data(record: dict[str, Any], trial: RouteTrial, label: str) -> TrialData:
    """The trial's summary and poses (a record that fits its schema:
    :class:`~homebench.experiments.route.records.RouteRecord`); ValueError when its
    intermediate positions are no frames of its route."""
    result = RouteResult(
        label, record["outbound"], record["homing"], record["intermediate"],
        record["odometry"], trial=trial.name, planned_length_m=trial.length,
    )  # fmt: skip
    probes = record.get("probes") or None
    return TrialData(trial, label, {**record["summary"], "method": label}, result, probes)


def _load_trial(job: RouteJob, run_dir: Path) -> TrialData | str:
    """The trial of ``job``, or why it has none: "routes/x.json (trial x: missing)"."""
    record = job.read(run_dir)
    if isinstance(record, str):
        return record
    try:
        return _trial_data(record, job.trial, job.label)
    except ValueError as error:
        where = f"{job.result_path(run_dir).relative_to(run_dir).as_posix()}"
        return f"{where} (trial {job.trial.name}: corrupt, {error})"


def load_route_run(info: RunInfo) -> RouteRun:
    """The trials of the route run ``info``; DataError when its config is invalid or no
    trial has a valid file."""
    try:
        config = ResolvedRouteConfig.model_validate(info.config)
    except ValidationError as error:
        raise validation_error(info.run_dir / CONFIG_FILE, "", error) from None
    trials, warnings = [], []
    plan = route_jobs(config)
    for job in plan:
        loaded = _load_trial(job, info.run_dir)
        (warnings if isinstance(loaded, str) else trials).append(loaded)
    if not trials:
        shown = "; ".join(warnings[:3]) + (" ..." if len(warnings) > 3 else "")
        raise DataError(f"{info.run_dir}: no trial results to report on (missing: {shown})")
    return RouteRun(info, config, trials, len(plan), warnings)


# --------------------------------------------------------------------------- title page


def _params(model: BaseModel) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in sorted(model.model_dump(mode="json").items()))


def _tracker_text(params: dict[str, Any]) -> str:
    if not params:
        return "KltTracker defaults"
    return ", ".join(f"{k}={v!r}" for k, v in sorted(params.items()))


def _route_line(route: RouteSpec) -> str:
    heading = (
        "along the first segment" if route.heading_deg is None else f"{route.heading_deg:g} deg"
    )
    if route.is_recorded:
        lengths = ", ".join(f"{x:g}" for x in route.lengths or ())
        over = f"the first {lengths} m" if lengths else "the whole route"
        return (
            f"route {route.name}: the database's recorded poses in recording order (replayed), "
            f"heading {heading}; trials over {over}, {route.repeats} each"
        )
    lengths = ", ".join(f"{x:g}" for x in route.trial_lengths())
    return (
        f"route {route.name}: {len(route.waypoints)} waypoints, {route.length:.2f} m, home "
        f"({route.waypoints[0][0]:g}, {route.waypoints[0][1]:g}) m, heading {heading}; "
        f"trials over the first {lengths} m, {route.repeats} each"
    )


def _method_lines(frame: pd.DataFrame, label: str) -> list[str]:
    reached = int((frame["visual_status"] == REACHED).sum())
    visual = 100 * frame["visual_error_m"].astype(float)
    odometry = 100 * frame["odometry_error_m"].astype(float)
    return [
        f"visual homing ({label}) reached home in {reached} of {len(frame)} trials",
        f"final position error, median over trials: visual {visual.median():.2f} cm, odometry "
        f"{odometry.median():.2f} cm (max {visual.max():.2f} and {odometry.max():.2f} cm)",
    ]


def _results_lines(run: RouteRun) -> list[str]:
    frame = trial_frame(run)
    missing = len(run.warnings)
    lines = [
        f"{len(run.trials)} of {run.planned} planned trials; missing or corrupt trial files: "
        f"{missing}{' (see the next page)' if missing else ''}",
    ]
    for label in run.labels:
        mine = frame[frame["method"] == label]
        if not mine.empty:
            lines += _method_lines(mine, label)
    return lines


def _experiment_lines(run: RouteRun) -> list[str]:
    """What the methods do: klt-sector's route homing and/or the snapshot route homing."""
    lines = []
    if KLT_SECTOR in {name for _, name, _ in run.config.method_points()}:
        lines.append(
            "route homing (seed 000): outbound route with KLT tracking, intermediate positions "
            "from the feature life-cycles, homing leg by leg with the sector law; odometry "
            "homing from the same end pose as the baseline"
        )
    pairwise = [label for label, name, _ in run.config.method_points() if name != KLT_SECTOR]
    if pairwise:
        lines += [
            f"route homing with pairwise methods ({', '.join(pairwise)}): snapshots stored on "
            "the outbound route, homing leg by leg from snapshot to snapshot; odometry homing "
            "from the same end pose as the baseline",
            f"pairwise homing: {_params(run.config.pairwise)}",
        ]
    if run.compared:
        lines.append(f"success: final position within {run.config.success_radius_m:g} m of home")
    return lines


def _scene_line(c: RouteConfig) -> str:
    if c.database is not None:
        return f"grid database {c.database}: the robot sees the nearest grid image"
    room, camera = c.world.room_extent, c.world.camera
    return (
        f"world: generated, style {c.world.style}, variant {c.world.variant} (seed "
        f"{c.world.seed}), room {room.width:g} x {room.depth:g} x {room.height:g} m, panoramas "
        f"{c.world.unfolded.width} px wide, {camera.exposure} exposure"
    )


def route_summary(run: RouteRun) -> dict[str, list[str]]:
    """A route run's title page sections: heading -> lines (config, results, environment)."""
    c = run.config
    return {
        "Run": run_lines(run.info),
        "Experiment": [
            *_experiment_lines(run),
            _scene_line(c),
            *(_route_line(route) for route in c.routes),
            f"motion: {_params(c.motion)}",
            f"odometry drift: {_params(c.drift)}",
            f"tracker: {_tracker_text(c.tracker)}",
            f"homing: {_params(c.homing)}",
            f"seed: {c.seed}",
        ],
        "Results": _results_lines(run),
        "Environment": environment_lines(run.info),
    }


# --------------------------------------------------------------------------- tables


def trial_frame(run: RouteRun) -> pd.DataFrame:
    """The trials' summaries, one row per trial in plan order (the run's routes.csv)."""
    return pd.DataFrame([trial.summary for trial in run.trials])


def trials_view(run: RouteRun) -> TableView:
    """One row per trial (and method, when the run compares several): route length, features,
    intermediate positions, final errors."""
    columns = {"method": ("method", None, 1.0), **TRIAL_COLUMNS} if run.compared else TRIAL_COLUMNS
    frame, digits = scaled_columns(trial_frame(run), columns)
    title = "Route homing per trial: visual homing and odometry, final errors at home"
    return make_view("routes", title, frame, digits)


def by_length_view(run: RouteRun) -> TableView:
    """One row per route and planned length: trials, reached, mean and max final errors."""
    frame = trial_frame(run)
    frame["reached"] = frame["visual_status"] == REACHED
    numeric = [k for k, (_, rule, _) in TRIAL_COLUMNS.items() if rule is not None]
    frame[numeric] = frame[numeric].apply(pd.to_numeric, errors="coerce")
    groups = frame.groupby(["route", "length_m"], sort=False)
    table = groups.agg(
        trials=("trial", "size"),
        reached=("reached", "sum"),
        driven_m=("driven_m", "mean"),
        n_intermediate=("n_intermediate", "mean"),
        visual_mean=("visual_error_m", "mean"),
        visual_max=("visual_error_m", "max"),
        odometry_mean=("odometry_error_m", "mean"),
        odometry_max=("odometry_error_m", "max"),
        visual_heading=("visual_heading_error_deg", "mean"),
        odometry_heading=("odometry_heading_error_deg", "mean"),
    ).reset_index()
    shown, digits = scaled_columns(table, LENGTH_COLUMNS)
    title = "Route homing per route length (means over trials; length: planned, route: driven)"
    return make_view("routes_by_length", title, shown, digits)


def route_views(run: RouteRun) -> list[TableView]:
    """The report tables of a route run: per route length, then per trial; a run of several
    methods: per method, paired comparisons, per method and length, then per trial."""
    if not run.compared:
        return [by_length_view(run), trials_view(run)]
    jobs, radius = trial_frame(run), run.config.success_radius_m
    return [
        method_view(jobs, run.labels, radius),
        paired_view(jobs, run.labels, radius),
        length_view(jobs, run.labels, radius),
        trials_view(run),
    ]


# --------------------------------------------------------------------------- figures


def _pages(trials: Sequence[TrialData]) -> list[list[TrialData]]:
    """Trials on trajectory pages, in plan order: the repeats of one (route, length) together,
    several such groups on a page while they fit in PANELS_PER_PAGE panels, larger groups
    split over pages."""
    groups: dict[tuple[str, float], list[TrialData]] = {}
    for trial in trials:
        groups.setdefault((trial.trial.route, trial.trial.length), []).append(trial)
    pages: list[list[TrialData]] = []
    open_page = False  # whether the last page holds whole groups only
    for group in groups.values():
        whole = len(group) <= PANELS_PER_PAGE
        if whole and open_page and len(pages[-1]) + len(group) <= PANELS_PER_PAGE:
            pages[-1] += group
        else:
            pages += [group[k : k + PANELS_PER_PAGE] for k in range(0, len(group), PANELS_PER_PAGE)]
        open_page = whole
    return pages


def _page_name(page: Sequence[TrialData]) -> str:
    first, last = page[0].trial.name, page[-1].trial.name
    return first if first == last else f"{first} to {last}"


def _compared_figures(run: RouteRun) -> Iterator[tuple[str, str, str, Figure]]:
    """A run of several methods: final errors with intervals, then per trial (the first of
    each route and length) one panel per method."""
    styles = method_styles(run.labels)
    caption = (
        "Final position error against route length per method and for odometry homing from "
        "the same end poses: mean over trials with its 95 % interval over trials"
    )
    figure = error_interval_figure(trial_frame(run), styles)
    yield "final_error_intervals", "Final errors", caption, figure
    caption = "Final position error against route length: every trial (hollow) and the means"
    figure = route_error_figure([trial.result for trial in run.trials], styles)
    yield "final_error", "Final errors", caption, figure
    firsts: dict[tuple[str, float], str] = {}
    for trial in run.trials:
        firsts.setdefault((trial.trial.route, trial.trial.length), trial.trial.name)
    for name in firsts.values():
        mine = [trial for trial in run.trials if trial.trial.name == name]
        results = [replace(t.result, trial=f"{name}: {t.label}") for t in mine]
        caption = f"Trajectories of trial {name}, one panel per method"
        yield f"trajectories_{name}", "Trajectories", caption, route_figure(results, styles)


def _ridf_figures(run: RouteRun) -> Iterator[tuple[str, str, str, Figure]]:
    """Per route-learning method, the RIDFs of its first probed trial at the probe station
    halfway along the route, one curve per distance beside it."""
    shown: set[str] = set()
    for trial in run.trials:
        if not trial.probes or trial.label in shown:
            continue
        shown.add(trial.label)
        stations = sorted({row["along_m"] for row in trial.probes})
        along = stations[len(stations) // 2]
        caption = (
            f"Rotational image difference functions of {trial.label}, trial {trial.trial.name}, "
            f"{along:g} m from home along the route: unfamiliarity against the direction "
            "relative to the route's way home, one curve per offset beside the route"
        )
        title = f"{trial.label}: RIDF {along:g} m from home"
        figure = ridf_figure(trial.probes, along, title)
        yield f"ridf_{trial.label}_{trial.trial.name}", "RIDFs", caption, figure


def route_run_figures(run: RouteRun) -> Iterator[tuple[str, str, str, Figure]]:
    """(file stem, section, caption, figure): the final errors, then the trajectories, then
    the route-learning methods' RIDFs."""
    yield from _run_figures(run)
    yield from _ridf_figures(run)


def _run_figures(run: RouteRun) -> Iterator[tuple[str, str, str, Figure]]:
    """The final errors, then the trajectories."""
    if run.compared:
        yield from _compared_figures(run)
        return
    label = run.labels[0]
    styles = method_styles([label])
    results = [trial.result for trial in run.trials]
    caption = (
        f"Final position error against route length: visual homing ({label}) and "
        "odometry homing from the same end pose"
    )
    yield "final_error", "Final errors", caption, route_error_figure(results, styles)
    for page in _pages(run.trials):
        name = _page_name(page)
        caption = f"Trajectories, trials {name}" if len(page) > 1 else f"Trajectory, trial {name}"
        stem = "trajectories_" + name.replace(" to ", "_to_")
        figure = route_figure([trial.result for trial in page], styles)
        yield stem, "Trajectories", caption, figure
