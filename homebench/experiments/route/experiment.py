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
import itertools
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from homebench.data.synth.world import PoseError
from homebench.errors import ConfigError
from homebench.evaluation.claims_record import ROUTE_RESULTS
from homebench.evaluation.code_version import code_version
from homebench.evaluation.executors import preload_for
from homebench.evaluation.jobs import JobOutcome, run_safely
from homebench.evaluation.plan import COMPASS_METHOD
from homebench.evaluation.runner import run_parallel
from homebench.experiments.homing import MethodHomer
from homebench.experiments.memory import MemoryGuide, facing, is_memory_method
from homebench.experiments.robot import DriftModel, Robot, dead_reckon
from homebench.experiments.route.config import KLT_SECTOR, RouteConfig, RouteSpec
from homebench.experiments.route.familiar import follow_home
from homebench.experiments.route.lifecycle import TargetSelectionError, select_targets
from homebench.experiments.route.outbound import (
    as_array,
    as_pose,
    drive_outbound,
    drive_route,
    path_length,
    route_prefix,
)
from homebench.experiments.route.pairwise import PairwiseHoming, Target, grey, home_pairwise
from homebench.experiments.route.probes import catchment, plan_probes, probe_route, probe_tables
from homebench.experiments.route.records import RouteRecord
from homebench.experiments.route.snapshots import SnapshotRule, similarity_frames, spacing_frames
from homebench.experiments.route.visual import home_visually
from homebench.experiments.scene import Camera, Scene, forget_databases, open_scene
from homebench.experiments.trials import (
    TrialFile,
    TrialRecord,
    TrialRunOutcome,
    robot_run_folder,
)
from homebench.fileio import make_folder, write_text_atomic
from homebench.geometry import FloatArray, Pose, angular_error
from homebench.hashing import derived_seed, stable_hash
from homebench.methods import registry
from homebench.methods.image_difference.visual_compass import CompassMode
from homebench.views import View

#: Bump when a trial's result changes for an unchanged config (invalidates finished trials).
ROUTE_FORMAT = 1
ROUTES_DIR = "routes"
TABLE_PATH = Path("tables") / "routes.csv"
#: The route-learning methods' probes (:mod:`~.probes`): one row per probe, per distance.
PROBES_PATH = Path("tables") / "route_probes.csv"
CATCHMENT_PATH = Path("tables") / "route_catchment.csv"
#: Spacing (metres) of the free-space checks along a route.
CHECK_SPACING = 0.01


@dataclass(frozen=True)
class RouteTrial:
    """One route driven for ``length`` metres: its ``waypoints`` (k, 2) and home ``heading``;
    ``displacement``: metres to the left of the last segment by which the robot is carried
    before it homes (None: no displacement planned, it homes from the route's end)."""

    name: str
    route: str
    length: float
    waypoints: tuple[tuple[float, float], ...]
    heading: float
    displacement: float | None = None

    @property
    def home(self) -> Pose:
        return Pose(*self.waypoints[0], self.heading)

    def homing_start(self, end: Pose) -> Pose:
        """Where homing starts: the route's true ``end`` moved ``displacement`` metres to the
        left of the last segment, heading unchanged (a passive displacement: the odometry is
        not told, as in the displacement experiments with ants)."""
        if not self.displacement:
            return end
        (x0, y0), (x1, y1) = self.waypoints[-2:]
        left = math.atan2(y1 - y0, x1 - x0) + math.pi / 2
        d = self.displacement
        return Pose(end.x + d * math.cos(left), end.y + d * math.sin(left), end.heading)


def world_routes(config: RouteConfig, config_path: Path | str = "config") -> list[RouteSpec]:
    """The config's routes with world-frame waypoints: grid-frame ones placed on the scene's
    capture grid, recorded ones along its recorded poses (a database is opened only when a
    route needs it). ConfigError naming the route when its database has no recorded poses."""
    if all(route.frame == "world" and not route.is_recorded for route in config.routes):
        return list(config.routes)
    scene = None if config.database is None else route_scene(config)
    origin = config.world.to_grid().origin if scene is None else scene.grid_origin
    routes = []
    for k, route in enumerate(config.routes):
        where = f"{config_path}: routes.{k} ({route.name})"
        if not route.is_recorded:
            routes.append(route.in_world(origin))
        elif scene is None or scene.recorded is None:
            raise ConfigError(
                f"{where}: waypoints 'recorded' follow a recorded route; database "
                f"{config.database!r} is a grid (give waypoints)"
            )
        else:
            routes.append(route.replayed(scene.recorded.xy, where, config.motion))
    return routes


def plan_trials(config: RouteConfig) -> list[RouteTrial]:
    """Every (route, length, repeat) of the config, in order.

    Names: the route's, then ``-<length>m`` when it has ``lengths``, then ``-d<metres>m`` when
    it has ``displacements_m``, then ``-r<k>`` when it has ``repeats`` > 1.
    """
    trials = []
    for route in world_routes(config):
        displacements = route.displacements_m or [None]
        for length, displacement in itertools.product(route.trial_lengths(), displacements):
            points = route_prefix(route.waypoints, length)
            waypoints = tuple((float(x), float(y)) for x, y in points)
            name = route.name if route.lengths is None else f"{route.name}-{length:g}m"
            name += "" if displacement is None else f"-d{displacement:g}m"
            for k in range(route.repeats):
                full = name if route.repeats == 1 else f"{name}-r{k}"
                trials.append(
                    RouteTrial(full, route.name, length, waypoints, route.heading, displacement)
                )
    return trials


@functools.cache
def _code(name: str) -> str:
    return code_version(registry.get(name))


@dataclass(frozen=True)
class RouteJob(TrialFile):
    """A trial homed by the method entry ``label`` of the config it runs under, and its key
    (a hash of all that decides it); its file's schema."""

    schema: ClassVar[type[TrialRecord]] = RouteRecord
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
        c, t = self.config, self.trial
        name, params = self.method
        decides = {
            "format": ROUTE_FORMAT,
            "scene": c.scene_key(),
            "seed": c.seed,
            "trial": [self.trial.name, self.trial.waypoints, self.trial.heading],
            **({} if t.displacement is None else {"displacement": t.displacement}),
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
                **(
                    {"familiarity": c.familiarity.model_dump(mode="json")}
                    if is_memory_method(name)
                    else {"pairwise": c.pairwise.model_dump(mode="json")}
                ),
            }
        return stable_hash(decides)

    def result_path(self, run_dir: Path) -> Path:
        folder = run_dir / ROUTES_DIR
        if len(self.config.method_points()) > 1:
            folder = folder / self.label
        return folder / f"{self.trial.name}.json"

    def names(self) -> dict[str, Any]:
        """The summary columns that say which job a file is of."""
        return {"trial": self.trial.name, "route": self.trial.route}


def route_jobs(config: RouteConfig) -> list[RouteJob]:
    """Every (trial, method) of ``config``, trial by trial, methods in config order."""
    labels = [label for label, _, _ in config.method_points()]
    return [RouteJob(config, trial, label) for trial in plan_trials(config) for label in labels]


def check_routes(config: RouteConfig, scene: Scene, config_path: Path) -> None:
    """ConfigError naming the route unless the scene can show every point along it and every
    displaced homing start (placed from the planned end of its trial's route)."""
    index = {route.name: k for k, route in enumerate(config.routes)}
    for k, route in enumerate(world_routes(config, config_path)):
        where = f"{config_path}: routes[{k}] ({route.name})"
        for (x0, y0), (x1, y1) in itertools.pairwise(route.waypoints):
            n = max(1, math.ceil(math.dist((x0, y0), (x1, y1)) / CHECK_SPACING))
            for t in range(n + 1):  # one point at a time: the first outside ends the check
                _check_pose(scene, Pose(x0 + t / n * (x1 - x0), y0 + t / n * (y1 - y0)), where)
    for trial in plan_trials(config):
        if trial.displacement:
            start = trial.homing_start(Pose(*trial.waypoints[-1]))
            route = f"routes[{index[trial.route]}] ({trial.route})"
            where = f"{config_path}: {route}: trial {trial.name}'s homing start"
            _check_pose(scene, start, where)


def _check_pose(scene: Scene, pose: Pose, where: str) -> None:
    """ConfigError starting with ``where`` unless the scene can show ``pose``."""
    try:
        scene.check_pose(pose)
    except PoseError as error:
        raise ConfigError(f"{where}: {error}") from None


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


def _homing_robot(config: RouteConfig, trial: RouteTrial, driver: Robot, stream: int) -> Robot:
    """A robot at the trial's homing start (the route's end, or displaced from it) with the
    driver's odometry, its noise from random stream ``stream`` of the trial."""
    rng = np.random.default_rng([derived_seed(config.seed, trial.name), stream])
    return Robot(trial.homing_start(driver.pose), driver.odometry, config.drift, rng)


def _odometry_baseline(
    config: RouteConfig, trial: RouteTrial, driver: Robot
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Dead reckoning home from the homing start: its summary columns and its arrays."""
    home = trial.home
    odometry = _homing_robot(config, trial, driver, 2)
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


def _summary_head(trial: RouteTrial, label: str, driven: FloatArray) -> dict[str, Any]:
    """The first columns of a trial's summary: trial, method, route, lengths, displacement
    (when the route plans displacements)."""
    head = {"trial": trial.name, "method": label, "route": trial.route, "length_m": trial.length}
    if trial.displacement is not None:
        head["displacement_m"] = trial.displacement
    return {**head, "driven_m": path_length(driven), "frames": len(driven)}


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

    visual = _homing_robot(config, trial, driver, 1)
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
    odometry, odometry_arrays = _odometry_baseline(config, trial, driver)
    summary = {
        **_summary_head(trial, label, outbound.poses),
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


@dataclass(frozen=True)
class _Drive:
    """A trial's outbound drive for the followers: the ``driver`` at the route's end, true
    ``poses`` and odometry ``belief`` (n, 3), and when it started."""

    driver: Robot
    poses: FloatArray
    belief: FloatArray
    started: float


def _drive(config: RouteConfig, trial: RouteTrial) -> _Drive:
    seed = derived_seed(config.seed, trial.name)
    started = time.perf_counter()
    driver = Robot.at(trial.home, config.drift, np.random.default_rng([seed, 0]))
    poses, belief = drive_route(driver, trial.waypoints, config.motion)
    return _Drive(driver, poses, belief, started)


def _follower_record(
    job: RouteJob, drive: _Drive, homing: PairwiseHoming, frames: list[int],
    visits: list[int], outbound_s: float, **extra: Any,
) -> dict[str, Any]:  # fmt: skip
    """The record of a trial homed through stored views (pairwise snapshots or a route
    memory's training views: their ``frames``, the targets in visiting order ``visits``);
    ``extra``: more summary columns (``columns``) and record fields."""
    trial, label = job.trial, job.label
    homing_s = time.perf_counter() - drive.started - outbound_s
    odometry, odometry_arrays = _odometry_baseline(job.config, trial, drive.driver)
    summary = {
        **_summary_head(trial, label, drive.poses),
        "features": None,  # klt-sector's columns, none here
        "features_home": None,
        "min_shared": None,
        "snapshots": len(frames),
        "n_intermediate": len(visits) - 1,
        **_visual_summary(homing.poses, trial.home, homing.status, len(homing.legs)),
        **odometry,
        **extra.pop("columns", {}),
    }
    record = {
        **_record_head(trial, label),
        "outbound": drive.poses.tolist(),
        "outbound_odometry": drive.belief.tolist(),
        "snapshots": frames,
        "targets": visits,
        "intermediate": visits[:-1],
        "homing": as_array(homing.poses).tolist(),
        "legs": homing.legs_as_dicts(),
        **odometry_arrays,
        "note": "",
        **extra,
        "summary": summary,
        "timing": {"outbound_s": outbound_s, "homing_s": homing_s},
    }
    return _finite(record)


def run_pairwise_trial(config: RouteConfig, trial: RouteTrial, label: str) -> dict[str, Any]:
    """Drive, store snapshots, home through them with the pairwise method of entry ``label``
    and by odometry; the trial's record (JSON-ready)."""
    job = RouteJob(config, trial, label)
    name, params = job.method
    method = registry.create(name, **params)
    seed = derived_seed(config.seed, trial.name)
    scene = route_scene(config)
    drive = _drive(config, trial)
    rule = config.pairwise.snapshots
    camera = scene.camera(seed, "outbound")
    frames, images = snapshot_frames(drive.poses, drive.belief, camera, rule)
    targets = [
        Target(
            k, images[k], _homer(method, job.compass, View(images[k], scene.geometry), pose), pose
        )
        for k in reversed(frames)
        for pose in [as_pose(drive.poses[k])]
    ]
    outbound_s = time.perf_counter() - drive.started
    visual = _homing_robot(config, trial, drive.driver, 1)
    homing = home_pairwise(
        visual, targets, scene.camera(seed, "homing"), config.motion, config.pairwise
    )
    visits = [target.frame for target in targets]
    return _follower_record(job, drive, homing, frames, visits, outbound_s)


def run_memory_trial(config: RouteConfig, trial: RouteTrial, label: str) -> dict[str, Any]:
    """Drive, learn every outbound view facing home, follow the memory of the route-learning
    method of entry ``label`` home (:mod:`~.familiar`), probe its heading field when the
    config asks (:mod:`~.probes`), and home by odometry; the trial's record (JSON-ready)."""
    job = RouteJob(config, trial, label)
    name, params = job.method
    method = registry.create(name, **params)
    seed = derived_seed(config.seed, trial.name)
    scene = route_scene(config)
    geometry = scene.geometry
    drive = _drive(config, trial)
    camera = scene.camera(seed, "outbound")
    images = [grey(camera(as_pose(pose), k)) for k, pose in enumerate(drive.poses)]
    guide = MemoryGuide.trained(method, [facing(i, geometry, math.pi) for i in images], geometry)
    homer = MethodHomer(method, method.describe(View(images[0], geometry)), geometry)
    home = Target(0, images[0], homer, trial.home)
    outbound_s = time.perf_counter() - drive.started
    visual = _homing_robot(config, trial, drive.driver, 1)
    follow = config.familiarity
    homing = follow_home(
        visual, guide, home, scene.camera(seed, "homing"), config.motion, follow,
        len(images), (trial.home.x, trial.home.y),
    )  # fmt: skip
    extra = {} if follow.probes is None else _probes(job, drive, guide, scene)
    frames = list(range(len(images)))
    return _follower_record(job, drive, homing, frames, [0], outbound_s, **extra)


def _probes(job: RouteJob, drive: _Drive, guide: MemoryGuide, scene: Scene) -> dict[str, Any]:
    """The probe rows of a memory trial (record field ``probes``) and its summary columns:
    the median error on the route and the catchment."""
    spec = job.config.familiarity.probes
    assert spec is not None
    seed = derived_seed(job.config.seed, job.trial.name)
    probes = plan_probes(drive.poses, spec, derived_seed(seed, "probes"))
    camera = scene.camera(seed, "probes")
    rows = probe_route(probes, camera, guide.method, guide.memory, scene.geometry)
    reach, table = catchment(rows, spec.threshold_deg)
    on_route = next((entry for entry in table if entry["distance_m"] == 0), None)
    columns = {
        "probe_error_on_route_deg": None if on_route is None else on_route["median_error_deg"],
        "catchment_m": reach,
    }
    return {"columns": columns, "probes": rows, "catchment": table}


def _run_and_write(job: RouteJob, run_dir: Path) -> None:
    name, _ = job.method
    run = (
        run_trial
        if name == KLT_SECTOR
        else run_memory_trial
        if is_memory_method(name)
        else run_pairwise_trial
    )
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
    """Run every unfinished trial of ``config`` and write the routes table; a trial running
    longer than the config's ``job_timeout_s`` fails."""
    forget_databases()  # read as they are now: an edited database gives other keys
    check_routes(config, route_scene(config), config_path)
    with robot_run_folder(config, config_path, ROUTE_RESULTS, force) as run_dir:
        return _run_route_trials(config, run_dir, jobs, force, show_progress)


def _run_route_trials(
    config: RouteConfig, run_dir: Path, jobs: int | None, force: bool, show_progress: bool
) -> TrialRunOutcome:
    """The trials of a route run in its claimed ``run_dir``, and its tables."""
    plan = route_jobs(config)
    if force:
        for job in plan:
            job.result_path(run_dir).unlink(missing_ok=True)
    todo = [job for job in plan if job.record(run_dir) is None]
    n_jobs = jobs if jobs is not None else config.jobs
    preload = preload_for(config.methods)
    outcomes = run_parallel(
        run_route_job, todo, run_dir, n_jobs, "routes", show_progress, preload,
        config.job_timeout_s, len(plan) - len(todo),
    )  # fmt: skip
    records = [job.record(run_dir) for job in plan]
    table = route_table([r for r in records if r is not None], config.success_radius_m)
    table_path = run_dir / TABLE_PATH
    table_path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(table_path, table.to_csv(index=False))
    probes, distances = probe_tables([r for r in records if r is not None])
    for path, frame in ((PROBES_PATH, probes), (CATCHMENT_PATH, distances)):
        if not frame.empty:
            write_text_atomic(run_dir / path, frame.to_csv(index=False))
    failures = tuple(outcome for outcome in outcomes if outcome.error)
    computed = len(todo) - len(failures)
    return TrialRunOutcome(run_dir, table, table_path, computed, len(plan) - len(todo), failures,
                           odometry_notes(config.drift))  # fmt: skip


def odometry_notes(drift: DriftModel) -> tuple[str, ...]:
    """A note when ``drift`` is none (a config without ``drift:``): the odometry baseline is
    then perfect, and its zero error is no finding."""
    if drift != DriftModel():
        return ()
    return (
        "odometry is perfect here (the config gives no drift: section): the odometry baseline "
        "knows the robot's true motion, so its error is 0 but for a passive displacement; give "
        "drift: for odometry that errs",
    )


def route_scene(config: RouteConfig) -> Scene:
    """The scene of a route config: its ``database`` if it names one (a grid, or a recorded
    route shown within ``recorded_reach_m``), else its world."""
    return open_scene(
        config.world, config.database, config.database_path, config.unfold, config.recorded_reach_m
    )
