"""The route-homing experiment of seed 000: trials, their result files, the routes table.

A trial = one route driven for one length. It drives the outbound route in the generated world
(:mod:`~.outbound`), chooses the intermediate positions from the feature life-cycles
(:mod:`~.lifecycle`), homes leg by leg with the sector law (:mod:`~.visual`) and, from the
same end pose and odometry, homes by dead reckoning (the odometry baseline). Everything is
seeded from the config's seed and the trial's name, so a rerun gives identical numbers.

Files in the run folder: ``routes/<trial>.json`` per trial (written atomically; a rerun skips
trials whose file holds the same key), ``tables/routes.csv``, and the run metadata. A trial's
JSON holds plain arrays, poses as (n, 3) rows (x [m], y [m], heading [rad]): ``outbound`` and
``outbound_odometry``, ``homing`` (the visual run from the route's end), ``odometry`` (the
baseline's true path) and ``odometry_belief``, ``intermediate`` (indices into ``outbound``,
in visiting order, home excluded), ``lifecycles`` (id, first frame, last frame), ``legs`` and a
``summary`` (the table's row).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from homebench.data.synth.world import PoseError
from homebench.errors import ConfigError
from homebench.evaluation.jobs import JobOutcome, run_safely
from homebench.evaluation.runner import run_parallel, write_run_metadata
from homebench.experiments.robot import Robot, dead_reckon
from homebench.experiments.route.config import RouteConfig, RouteSpec
from homebench.experiments.route.lifecycle import TargetSelectionError, select_targets
from homebench.experiments.route.outbound import (
    as_array,
    drive_outbound,
    path_length,
    route_prefix,
)
from homebench.experiments.route.visual import home_visually
from homebench.experiments.scene import Scene, open_scene
from homebench.fileio import read_json_record, write_text_atomic
from homebench.geometry import Pose, angular_error
from homebench.hashing import derived_seed, stable_hash

#: Bump when a trial's result changes for an unchanged config (invalidates finished trials).
ROUTE_FORMAT = 1
ROUTES_DIR = "routes"
TABLE_PATH = Path("tables") / "routes.csv"
#: Spacing (metres) of the free-space checks along a route.
CHECK_SPACING = 0.01


@dataclass(frozen=True)
class RouteTrial:
    """One route driven for ``length`` metres: its ``waypoints`` (k, 2) and home ``heading``."""

    name: str
    route: str
    length: float
    waypoints: tuple[tuple[float, float], ...]
    heading: float

    @property
    def home(self) -> Pose:
        return Pose(*self.waypoints[0], self.heading)


def world_routes(config: RouteConfig) -> list[RouteSpec]:
    """The config's routes with world-frame waypoints (grid-frame ones placed on the scene's
    capture grid; a database is opened only when a route needs its grid)."""
    if all(route.frame == "world" for route in config.routes):
        return list(config.routes)
    if config.database is None:
        origin = config.world.to_grid().origin
    else:
        origin = route_scene(config).grid_origin
    return [route.in_world(origin) for route in config.routes]


def plan_trials(config: RouteConfig) -> list[RouteTrial]:
    """Every (route, length, repeat) of the config, in order.

    Names: the route's, then ``-<length>m`` when it has ``lengths``, then ``-r<k>`` when it
    has ``repeats`` > 1.
    """
    trials = []
    for route in world_routes(config):
        for length in route.trial_lengths():
            points = route_prefix(route.waypoints, length)
            waypoints = tuple((float(x), float(y)) for x, y in points)
            name = route.name if route.lengths is None else f"{route.name}-{length:g}m"
            for k in range(route.repeats):
                full = name if route.repeats == 1 else f"{name}-r{k}"
                trials.append(RouteTrial(full, route.name, length, waypoints, route.heading))
    return trials


@dataclass(frozen=True)
class RouteJob:
    """A trial with the config it runs under and its key (a hash of all that decides it)."""

    config: RouteConfig
    trial: RouteTrial

    @property
    def key(self) -> str:
        c = self.config
        return stable_hash(
            {
                "format": ROUTE_FORMAT,
                "scene": c.scene_key(),
                "seed": c.seed,
                "trial": [self.trial.name, self.trial.waypoints, self.trial.heading],
                "motion": c.motion.model_dump(mode="json"),
                "drift": c.drift.model_dump(mode="json"),
                "tracker": c.tracker,
                "homing": c.homing.model_dump(mode="json"),
            }
        )

    def result_path(self, run_dir: Path) -> Path:
        return run_dir / ROUTES_DIR / f"{self.trial.name}.json"


def check_routes(config: RouteConfig, scene: Scene, config_path: Path) -> None:
    """ConfigError naming the route unless the scene can show every point along it."""
    for k, route in enumerate(config.routes):
        points = np.asarray(route.in_world(scene.grid_origin).waypoints, dtype=np.float64)
        for a, b in zip(points[:-1], points[1:], strict=True):
            n = max(1, math.ceil(math.dist(a, b) / CHECK_SPACING))
            for x, y in a + np.linspace(0.0, 1.0, n + 1)[:, None] * (b - a):
                try:
                    scene.check_pose(Pose(float(x), float(y)))
                except PoseError as error:
                    raise ConfigError(
                        f"{config_path}: routes[{k}] ({route.name}): {error}"
                    ) from None


def _degrees_error(heading: float, truth: float) -> float:
    return math.degrees(float(angular_error(heading, truth)))


def _finite(value: Any) -> Any:
    """``value`` with every non-finite float replaced by None (strict JSON)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    if isinstance(value, float | np.floating):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def run_trial(config: RouteConfig, trial: RouteTrial) -> dict[str, Any]:
    """Drive, track, home visually and by odometry; the trial's record (JSON-ready)."""
    seed = derived_seed(config.seed, trial.name)
    scene = route_scene(config)
    tracker = config.klt()
    home = trial.home
    started = time.perf_counter()
    driver = Robot.at(home, config.drift, np.random.default_rng([seed, 0]))
    outbound = drive_outbound(
        driver, trial.waypoints, config.motion, scene.camera(seed, "outbound"), tracker
    )
    outbound_s = time.perf_counter() - started
    lifecycles = outbound.log.lifecycles()

    visual = Robot(driver.pose, driver.odometry, config.drift, np.random.default_rng([seed, 1]))
    try:
        targets = select_targets(lifecycles, outbound.end, config.homing.min_shared)
        homing = home_visually(
            visual, outbound, targets, scene.camera(seed, "homing"), tracker,
            scene.geometry, config.motion, config.homing,
        )  # fmt: skip
        status, poses, legs, note = homing.status, homing.poses, homing.legs_as_dicts(), ""
    except TargetSelectionError as error:
        targets, status, poses, legs, note = [], "no_targets", [visual.pose], [], str(error)
    homing_s = time.perf_counter() - started - outbound_s

    odometry = Robot(driver.pose, driver.odometry, config.drift, np.random.default_rng([seed, 2]))
    odometry_poses, belief = dead_reckon(odometry, home, config.motion)

    end = poses[-1]
    summary = {
        "trial": trial.name,
        "route": trial.route,
        "length_m": trial.length,
        "driven_m": path_length(outbound.poses),
        "frames": len(outbound.images),
        "features": len(lifecycles),
        "features_home": len(outbound.log.frames[0][0]),
        "min_shared": config.homing.min_shared,
        "n_intermediate": max(len(targets) - 1, 0),
        "visual_status": status,
        "visual_steps": len(poses) - 1,
        "visual_error_m": math.dist(end.xy, home.xy),
        "visual_heading_error_deg": _degrees_error(end.heading, home.heading),
        "odometry_error_m": math.dist(odometry.pose.xy, home.xy),
        "odometry_heading_error_deg": _degrees_error(odometry.pose.heading, home.heading),
        "odometry_drift_at_end_m": math.dist(driver.pose.xy, driver.odometry.xy),
    }
    record = {
        "format": ROUTE_FORMAT,
        "trial": trial.name,
        "waypoints": [list(p) for p in trial.waypoints],
        "home": [home.x, home.y, home.heading],
        "outbound": outbound.poses.tolist(),
        "outbound_odometry": outbound.odometry.tolist(),
        "lifecycles": lifecycles.tolist(),
        "targets": targets,
        "intermediate": targets[:-1],
        "homing": as_array(poses).tolist(),
        "legs": legs,
        "odometry": as_array(odometry_poses).tolist(),
        "odometry_belief": as_array(belief).tolist(),
        "note": note,
        "summary": summary,
        "timing": {"outbound_s": outbound_s, "homing_s": homing_s},
    }
    return _finite(record)


def _run_and_write(job: RouteJob, run_dir: Path) -> None:
    record = {"key": job.key, **run_trial(job.config, job.trial)}
    path = job.result_path(run_dir)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(record, allow_nan=False) + "\n")


def run_route_job(job: RouteJob, run_dir: Path) -> JobOutcome:
    """Run one trial in a worker and write its file; failures come back in the outcome."""
    return run_safely("route", job.key, _run_and_write, job, run_dir)


def route_table(records: list[dict[str, Any]]) -> pd.DataFrame:
    """One row per trial: the records' summaries."""
    return pd.DataFrame([record["summary"] for record in records])


@dataclass(frozen=True)
class RouteRunOutcome:
    """What the CLI prints: the ``table`` (written to ``table_path``), counts and failures."""

    run_dir: Path
    table: pd.DataFrame
    table_path: Path
    computed: int
    reused: int
    failures: tuple[JobOutcome, ...]


def run_route_experiment(
    config: RouteConfig,
    config_path: Path,
    jobs: int | None = None,
    force: bool = False,
    show_progress: bool = True,
) -> RouteRunOutcome:
    """Run every unfinished trial of ``config`` and write the routes table."""
    check_routes(config, route_scene(config), config_path)
    run_dir = Path(config.output)
    run_dir.mkdir(parents=True, exist_ok=True)
    write_run_metadata(config, config_path, run_dir)
    plan = [RouteJob(config, trial) for trial in plan_trials(config)]
    if force:
        for job in plan:
            job.result_path(run_dir).unlink(missing_ok=True)
    todo = [job for job in plan if read_json_record(job.result_path(run_dir), job.key) is None]
    n_jobs = jobs if jobs is not None else config.jobs
    outcomes = run_parallel(run_route_job, todo, run_dir, n_jobs, "routes", show_progress)
    records = [read_json_record(job.result_path(run_dir), job.key) for job in plan]
    table = route_table([r for r in records if r is not None])
    table_path = run_dir / TABLE_PATH
    table_path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(table_path, table.to_csv(index=False))
    failures = tuple(outcome for outcome in outcomes if outcome.error)
    return RouteRunOutcome(run_dir, table, table_path, len(todo), len(plan) - len(todo), failures)


def route_scene(config: RouteConfig) -> Scene:
    """The scene of a route config: its grid ``database`` if it names one, else its world."""
    return open_scene(config.world, config.database, config.database_path, config.unfold)
