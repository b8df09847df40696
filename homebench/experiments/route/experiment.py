"""The route-homing experiment of seed 000: trials, their result files, the routes table.

A trial = one route driven for one length; a job = one trial homed by one method of the config.
Every job drives the same outbound route (the drive is seeded from the config's seed and the
trial's name, and does not depend on what the robot sees), homes with its method from the
route's end, and homes by dead reckoning from the same end pose and odometry (the odometry
baseline, the same in every job of a trial). So all methods are compared on the same routes,
and a rerun gives identical numbers.

- ``klt-sector`` (seed 000's own route homing): KLT tracking on the way out
  (:mod:`~.outbound`), intermediate positions from the feature life-cycles (:mod:`~.lifecycle`),
  the sector law leg by leg (:mod:`~.visual`).
- Any other (pairwise) method: snapshots stored on the way out (:mod:`~.snapshots`), homing leg
  by leg from snapshot to snapshot (:mod:`~.pairwise`).

Files in the run folder: ``routes/<trial>.json`` per trial when the config has one method,
``routes/<label>/<trial>.json`` per method and trial when it has several (written atomically;
a rerun skips jobs whose file holds the same key), ``tables/routes.csv`` (one row per job, its
``success``: the final position within ``success_radius_m`` of home), and the run metadata.
A trial's JSON holds plain arrays, poses as (n, 3) rows (x [m], y [m], heading [rad]):
``outbound`` and ``outbound_odometry``, ``homing`` (the visual run from the route's end),
``odometry`` (the baseline's true path) and ``odometry_belief``, ``targets`` (indices into
``outbound`` in visiting order, home last) and ``intermediate`` (the same without home),
``legs`` and a ``summary`` (the table's row); klt-sector's also ``lifecycles`` (id, first
frame, last frame), a pairwise method's ``snapshots`` (frames, ascending).
"""

from __future__ import annotations

import functools
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
from homebench.evaluation.code_version import code_version
from homebench.evaluation.executors import preload_for
from homebench.evaluation.jobs import JobOutcome, run_safely
from homebench.evaluation.plan import COMPASS_METHOD
from homebench.evaluation.runner import run_parallel, write_run_metadata
from homebench.experiments.homing import MethodHomer
from homebench.experiments.robot import Robot, dead_reckon
from homebench.experiments.route.config import KLT_SECTOR, RouteConfig, RouteSpec
from homebench.experiments.route.lifecycle import TargetSelectionError, select_targets
from homebench.experiments.route.outbound import (
    as_array,
    as_pose,
    drive_outbound,
    drive_route,
    path_length,
    route_prefix,
)
from homebench.experiments.route.pairwise import Target, grey, home_pairwise
from homebench.experiments.route.snapshots import SnapshotRule, similarity_frames, spacing_frames
from homebench.experiments.route.visual import home_visually
from homebench.experiments.scene import Camera, Scene, open_scene
from homebench.experiments.trials import TrialRunOutcome
from homebench.fileio import make_folder, read_json_record, write_text_atomic
from homebench.geometry import FloatArray, Pose, angular_error
from homebench.hashing import derived_seed, stable_hash
from homebench.methods import registry
from homebench.methods.visual_compass import CompassMode
from homebench.views import View

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


@functools.cache
def _code(name: str) -> str:
    return code_version(registry.get(name))


@dataclass(frozen=True)
class RouteJob:
    """A trial homed by the method entry ``label`` of the config it runs under, and its key
    (a hash of all that decides it)."""

    config: RouteConfig
    trial: RouteTrial
    label: str = KLT_SECTOR

    @property
    def method(self) -> tuple[str, dict[str, Any]]:
        """(registered name, params) of the job's method."""
        points = {label: (name, params) for label, name, params in self.config.method_points()}
        return points[self.label]

    @property
    def compass(self) -> CompassMode:
        """The job's method entry's compass."""
        entries = {label: e for e in self.config.methods for label, _ in e.expand()}
        return entries[self.label].compass if self.label in entries else "none"

    @property
    def key(self) -> str:
        c = self.config
        name, params = self.method
        decides = {
            "format": ROUTE_FORMAT,
            "scene": c.scene_key(),
            "seed": c.seed,
            "trial": [self.trial.name, self.trial.waypoints, self.trial.heading],
            "motion": c.motion.model_dump(mode="json"),
            "drift": c.drift.model_dump(mode="json"),
        }
        if name == KLT_SECTOR:  # the same keys as before route runs had other methods
            decides |= {"tracker": c.tracker, "homing": c.homing.model_dump(mode="json")}
        else:
            decides |= {
                "method": {"name": name, "params": params, "code": _code(name)},
                **(
                    {"compass": [self.compass, _code(COMPASS_METHOD)]}
                    if self.compass != "none"
                    else {}
                ),
                "pairwise": c.pairwise.model_dump(mode="json"),
            }
        return stable_hash(decides)

    def result_path(self, run_dir: Path) -> Path:
        folder = run_dir / ROUTES_DIR
        if len(self.config.method_points()) > 1:
            folder = folder / self.label
        return folder / f"{self.trial.name}.json"


def route_jobs(config: RouteConfig) -> list[RouteJob]:
    """Every (trial, method) of ``config``, trial by trial, methods in config order."""
    labels = [label for label, _, _ in config.method_points()]
    return [RouteJob(config, trial, label) for trial in plan_trials(config) for label in labels]


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


def _visual_summary(poses: list[Pose], home: Pose, status: str, legs: int) -> dict[str, Any]:
    """The homing run's columns of a trial's summary."""
    end = poses[-1]
    return {
        "visual_status": status,
        "visual_steps": len(poses) - 1,
        "visual_error_m": math.dist(end.xy, home.xy),
        "visual_heading_error_deg": _degrees_error(end.heading, home.heading),
        "visual_path_m": path_length(as_array(poses)),
        "legs": legs,
    }


def _odometry_baseline(
    config: RouteConfig, driver: Robot, home: Pose, seed: int
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Dead reckoning home from the driver's end pose: its summary columns and its arrays."""
    odometry = Robot(driver.pose, driver.odometry, config.drift, np.random.default_rng([seed, 2]))
    odometry_poses, belief = dead_reckon(odometry, home, config.motion)
    summary = {
        "odometry_error_m": math.dist(odometry.pose.xy, home.xy),
        "odometry_heading_error_deg": _degrees_error(odometry.pose.heading, home.heading),
        "odometry_drift_at_end_m": math.dist(driver.pose.xy, driver.odometry.xy),
    }
    arrays = {
        "odometry": as_array(odometry_poses).tolist(),
        "odometry_belief": as_array(belief).tolist(),
    }
    return summary, arrays


def _record_head(trial: RouteTrial, label: str) -> dict[str, Any]:
    """The fields every trial record starts with: format, trial, method, route, home pose."""
    home = trial.home
    return {
        "format": ROUTE_FORMAT,
        "trial": trial.name,
        "method": label,
        "waypoints": [list(p) for p in trial.waypoints],
        "home": [home.x, home.y, home.heading],
    }


def run_trial(config: RouteConfig, trial: RouteTrial, label: str = KLT_SECTOR) -> dict[str, Any]:
    """Drive, track, home visually (klt-sector, the entry ``label``) and by odometry; the
    trial's record (JSON-ready)."""
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
    odometry, odometry_arrays = _odometry_baseline(config, driver, home, seed)
    summary = {
        "trial": trial.name,
        "method": label,
        "route": trial.route,
        "length_m": trial.length,
        "driven_m": path_length(outbound.poses),
        "frames": len(outbound.images),
        "features": len(lifecycles),
        "features_home": len(outbound.log.frames[0][0]),
        "min_shared": config.homing.min_shared,
        "n_intermediate": max(len(targets) - 1, 0),
        **_visual_summary(poses, home, status, len(legs)),
        **odometry,
    }
    record = {
        **_record_head(trial, label),
        "outbound": outbound.poses.tolist(),
        "outbound_odometry": outbound.odometry.tolist(),
        "lifecycles": lifecycles.tolist(),
        "targets": targets,
        "intermediate": targets[:-1],
        "homing": as_array(poses).tolist(),
        "legs": legs,
        **odometry_arrays,
        "note": note,
        "summary": summary,
        "timing": {"outbound_s": outbound_s, "homing_s": homing_s},
    }
    return _finite(record)


def snapshot_frames(
    poses: FloatArray, odometry: FloatArray, camera: Camera, rule: SnapshotRule
) -> tuple[list[int], dict[int, Any]]:
    """The snapshots of the outbound route (true ``poses`` and ``odometry`` (n, 3), frames
    seen by ``camera``) by ``rule``: their frames (ascending, 0 first, the last frame never)
    and grey images by frame."""
    if rule.rule == "spacing":
        frames = spacing_frames(odometry, rule.spacing_m)
        return frames, {k: grey(camera(as_pose(poses[k]), k)) for k in frames}
    images = [grey(camera(as_pose(pose), k)) for k, pose in enumerate(poses[:-1])]
    frames = similarity_frames(images, rule.threshold)
    return frames, {k: images[k] for k in frames}


def _homer(method: Any, compass: CompassMode, snapshot: View, pose: Pose) -> MethodHomer:
    """``method`` homing to ``snapshot``, taken at true ``pose``, with the entry's
    ``compass``."""
    features = method.describe(snapshot)
    return MethodHomer(method, features, snapshot.geometry, compass, pose.heading, snapshot)


def run_pairwise_trial(config: RouteConfig, trial: RouteTrial, label: str) -> dict[str, Any]:
    """Drive, store snapshots, home through them with the pairwise method of entry ``label``
    and by odometry; the trial's record (JSON-ready)."""
    job = RouteJob(config, trial, label)
    name, params = job.method
    method = registry.create(name, **params)
    seed = derived_seed(config.seed, trial.name)
    scene = route_scene(config)
    home = trial.home
    started = time.perf_counter()
    driver = Robot.at(home, config.drift, np.random.default_rng([seed, 0]))
    poses, belief = drive_route(driver, trial.waypoints, config.motion)
    rule = config.pairwise.snapshots
    frames, images = snapshot_frames(poses, belief, scene.camera(seed, "outbound"), rule)
    targets = [
        Target(
            k, images[k], _homer(method, job.compass, View(images[k], scene.geometry), pose), pose
        )
        for k in reversed(frames)
        for pose in [as_pose(poses[k])]
    ]
    outbound_s = time.perf_counter() - started
    visual = Robot(driver.pose, driver.odometry, config.drift, np.random.default_rng([seed, 1]))
    homing = home_pairwise(
        visual, targets, scene.camera(seed, "homing"), config.motion,
        config.pairwise,
    )  # fmt: skip
    homing_s = time.perf_counter() - started - outbound_s
    odometry, odometry_arrays = _odometry_baseline(config, driver, home, seed)
    visits = [target.frame for target in targets]
    summary = {
        "trial": trial.name,
        "method": label,
        "route": trial.route,
        "length_m": trial.length,
        "driven_m": path_length(poses),
        "frames": len(poses),
        "features": None,  # klt-sector's columns, none here
        "features_home": None,
        "min_shared": None,
        "snapshots": len(frames),
        "n_intermediate": len(frames) - 1,
        **_visual_summary(homing.poses, home, homing.status, len(homing.legs)),
        **odometry,
    }
    record = {
        **_record_head(trial, label),
        "outbound": poses.tolist(),
        "outbound_odometry": belief.tolist(),
        "snapshots": frames,
        "targets": visits,
        "intermediate": visits[:-1],
        "homing": as_array(homing.poses).tolist(),
        "legs": homing.legs_as_dicts(),
        **odometry_arrays,
        "note": "",
        "summary": summary,
        "timing": {"outbound_s": outbound_s, "homing_s": homing_s},
    }
    return _finite(record)


def _run_and_write(job: RouteJob, run_dir: Path) -> None:
    name, _ = job.method
    run = run_trial if name == KLT_SECTOR else run_pairwise_trial
    record = {"key": job.key, **run(job.config, job.trial, job.label)}
    path = job.result_path(run_dir)
    make_folder(path.parent)
    write_text_atomic(path, json.dumps(record, allow_nan=False) + "\n")


def run_route_job(job: RouteJob, run_dir: Path) -> JobOutcome:
    """Run one trial in a worker and write its file; failures come back in the outcome."""
    return run_safely("route", job.key, _run_and_write, job, run_dir)


def route_table(records: list[dict[str, Any]], success_radius_m: float) -> pd.DataFrame:
    """One row per job: the records' summaries, ``success`` when the final position is within
    ``success_radius_m`` of home."""
    table = pd.DataFrame([record["summary"] for record in records])
    if not table.empty:
        table["success"] = table["visual_error_m"].astype(float) <= success_radius_m
    return table


def run_route_experiment(
    config: RouteConfig,
    config_path: Path,
    jobs: int | None = None,
    force: bool = False,
    show_progress: bool = True,
) -> TrialRunOutcome:
    """Run every unfinished trial of ``config`` and write the routes table."""
    check_routes(config, route_scene(config), config_path)
    run_dir = Path(config.output)
    make_folder(run_dir)
    write_run_metadata(config, config_path, run_dir)
    plan = route_jobs(config)
    if force:
        for job in plan:
            job.result_path(run_dir).unlink(missing_ok=True)
    todo = [job for job in plan if read_json_record(job.result_path(run_dir), job.key) is None]
    n_jobs = jobs if jobs is not None else config.jobs
    preload = preload_for(config.methods)
    outcomes = run_parallel(run_route_job, todo, run_dir, n_jobs, "routes", show_progress, preload)
    records = [read_json_record(job.result_path(run_dir), job.key) for job in plan]
    table = route_table([r for r in records if r is not None], config.success_radius_m)
    table_path = run_dir / TABLE_PATH
    table_path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(table_path, table.to_csv(index=False))
    failures = tuple(outcome for outcome in outcomes if outcome.error)
    return TrialRunOutcome(run_dir, table, table_path, len(todo), len(plan) - len(todo), failures)


def route_scene(config: RouteConfig) -> Scene:
    """The scene of a route config: its grid ``database`` if it names one, else its world."""
    return open_scene(config.world, config.database, config.database_path, config.unfold)
