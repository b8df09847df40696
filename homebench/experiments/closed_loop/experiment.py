"""The closed-loop experiment: trials as jobs, one JSON file per trial, the run's tables.

A trial = one (style, method or control, goal, start). Its key hashes everything that decides
it, so a rerun skips trials whose file holds the same key (resumable), and the trials run in
isolated workers (:func:`homebench.evaluation.runner.run_parallel`). Everything is seeded from
the config's seed and the trial, so ``--jobs 1`` and ``--jobs 2`` give identical tables.

Files in the run folder: ``trials/<style>/<method>/g<goal>_s<start>.json`` per trial (written
atomically), ``views/`` (the rendered-view cache, :mod:`~.views`), ``tables/`` (see
:mod:`~.tables`) and the run metadata. A trial's JSON holds a ``summary`` (its row of
``trials.csv``) and ``trajectory``, the true poses as (n, 3) rows (x [m], y [m], heading [rad]).
"""

from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import PoseError
from homebench.errors import ConfigError
from homebench.evaluation.claims_record import CLOSED_LOOP_RESULTS
from homebench.evaluation.code_version import code_version, module_version
from homebench.evaluation.executors import preload_for
from homebench.evaluation.jobs import JobOutcome, run_safely
from homebench.evaluation.runner import run_parallel
from homebench.experiments.closed_loop.config import ClosedLoopConfig
from homebench.experiments.closed_loop.homers import Homer, MethodHomer, RandomHomer, TruthHomer
from homebench.experiments.closed_loop.loop import run_loop
from homebench.experiments.closed_loop.records import ClosedLoopRecord
from homebench.experiments.closed_loop.starts import Start, free_starts, goal_pose, goal_starts
from homebench.experiments.closed_loop.tables import TABLES_DIR, write_tables
from homebench.experiments.closed_loop.views import LatticeViews
from homebench.experiments.memory import MemoryGuide, is_memory_method
from homebench.experiments.robot import Robot
from homebench.experiments.scene import Scene, database_content, forget_databases, open_scene
from homebench.experiments.trials import (
    TrialFile,
    TrialRecord,
    TrialRunOutcome,
    robot_run_folder,
)
from homebench.fileio import make_folder, write_text_atomic
from homebench.geometry import Pose
from homebench.hashing import derived_seed, stable_hash
from homebench.methods import registry
from homebench.methods.image_difference.visual_compass import CompassMode, compass_turn
from homebench.views import View

#: Bump when a trial's result changes for an unchanged config (invalidates finished trials).
CLOSED_LOOP_FORMAT = 1
TRIALS_DIR = "trials"
VIEWS_DIR = "views"


@dataclass(frozen=True)
class Trial:
    """One trial: the world's ``style`` (or "database"), the ``label`` of a method (``method``
    its registered name, ``params`` and ``compass``) or control (``method`` None), ``goal``
    index and pose, and ``start``."""

    style: str
    label: str
    method: str | None
    params: tuple[tuple[str, Any], ...]
    compass: CompassMode
    goal: int
    goal_pose: Pose
    start: Start

    @property
    def name(self) -> str:
        return f"{self.style}/{self.label}/g{self.goal}_s{self.start.index:05d}"


def _folder_name(label: str) -> str:
    """A folder name for ``label``: safe characters, plus a hash when some were replaced."""
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", label)
    return safe if safe == label else f"{safe}-{stable_hash(label, 6)}"


def scene_key(config: ClosedLoopConfig, style: str) -> dict[str, Any]:
    """What identifies the scene of ``style`` in keys: the database and what it holds
    (:func:`~homebench.experiments.scene.database_content`), or the world's hash."""
    if config.database is not None:
        content = database_content(config.database, config.database_path)
        return {"database": config.database, "path": str(config.database_path), "content": content}
    return {"world": _world(config, style).key()}


def _world(config: ClosedLoopConfig, style: str) -> WorldSpec:
    return next(w for w in config.worlds() if w is not None and w.style == style)


def styles(config: ClosedLoopConfig) -> list[str]:
    """The run's style names, in config order ("database" for a database run)."""
    return config.style_names()


_scenes: dict[str, Scene] = {}


def trial_scene(config: ClosedLoopConfig, style: str) -> Scene:
    """The scene of ``style`` (opened once per process and scene)."""
    key = stable_hash(scene_key(config, style))
    if key not in _scenes:
        world = config.world if config.database is not None else _world(config, style)
        scene = open_scene(world, config.database, config.database_path, config.unfold)
        if scene.grid is None:  # starts and goals are placed on a capture grid
            raise ConfigError(
                f"database {config.database!r} is a recording (posed images, no grid): "
                "closed-loop runs need a grid database or a generated world; a route run "
                "(kind: route, waypoints: recorded) replays a recording"
            )
        _scenes[key] = scene
    return _scenes[key]


@dataclass(frozen=True)
class ClosedLoopJob(TrialFile):
    """A trial with the config it runs under and its key; its file's schema."""

    schema: ClassVar[type[TrialRecord]] = ClosedLoopRecord
    config: ClosedLoopConfig
    trial: Trial

    @property
    def key(self) -> str:
        c, t = self.config, self.trial
        return stable_hash(
            {
                "format": CLOSED_LOOP_FORMAT,
                "scene": scene_key(c, t.style),
                "seed": c.seed,
                "method": [t.label, t.method, dict(t.params), t.compass],
                "code": trial_code(t.method, t.compass),
                "goal": [t.goal_pose.x, t.goal_pose.y, t.goal_pose.heading],
                "start": [t.start.index, t.start.x, t.start.y, t.start.heading, t.start.area],
                "motion": c.motion.model_dump(mode="json"),
                "drift": c.drift.model_dump(mode="json"),
                "lattice": _lattice(c),
                **({"training": c.training.model_dump(mode="json")} if _learns(t) else {}),
            }
        )

    def result_path(self, run_dir: Path) -> Path:
        t = self.trial
        name = f"g{t.goal}_s{t.start.index:05d}.json"
        return run_dir / TRIALS_DIR / t.style / _folder_name(t.label) / name

    def names(self) -> dict[str, Any]:
        """The summary columns that say which trial a file is of."""
        t = self.trial
        return {"style": t.style, "method": t.label, "goal": t.goal, "start": t.start.index}


@functools.cache
def trial_code(method: str | None, compass: CompassMode) -> list[str]:
    """Code versions that decide a trial: the closed loop's own modules, the method's (none
    for a control) and the visual compass's when it turns the views."""
    codes = [module_version(__name__)]
    if method is not None:
        codes.append(code_version(registry.get(method)))
    if compass == "visual":
        codes.append(module_version(compass_turn.__module__))
    return codes


def _lattice(config: ClosedLoopConfig) -> float | None:
    """The view lattice's spacing (None: exact renders; grid databases snap to their grid)."""
    return None if config.database is not None else config.render.lattice


def plan_trials(config: ClosedLoopConfig) -> list[Trial]:
    """Every trial of ``config``: styles, goals, starts (free, far enough), then labels.

    ConfigError when a goal is not in free space.
    """
    trials = []
    points = {
        label: (entry.method, params, entry.compass)
        for entry in config.methods
        for label, params in entry.expand()
    }
    for style in styles(config):
        scene = trial_scene(config, style)
        starts = free_starts(config, scene)
        for k, goal in enumerate(config.goals):
            pose = goal_pose(config, goal, scene)
            try:
                scene.check_pose(pose)
            except PoseError as error:
                raise ConfigError(f"goals[{k}] ({style}): {error}") from None
            for start in goal_starts(starts, pose, config.motion.start_floor):
                for label in config.labels():
                    method, params, compass = points.get(label, (None, {}, "none"))
                    parameters = tuple(sorted(params.items()))
                    trials.append(Trial(style, label, method, parameters, compass, k, pose, start))
    return trials


_views: dict[str, LatticeViews] = {}
_goals: dict[str, tuple[View, Any]] = {}


def _lattice_views(config: ClosedLoopConfig, style: str, run_dir: Path) -> LatticeViews:
    key = stable_hash({"scene": scene_key(config, style), "seed": config.seed,
                       "lattice": _lattice(config), "run": str(run_dir)})  # fmt: skip
    if key not in _views:
        spacing = _lattice(config)
        cache = stable_hash([scene_key(config, style), config.seed, spacing])
        folder = run_dir / VIEWS_DIR / cache if spacing is not None else None
        _views[key] = LatticeViews(
            trial_scene(config, style), spacing, folder, config.render.cache_mb * 1e6,
            config.render.memory_views, derived_seed(config.seed, "views"),
        )  # fmt: skip
    return _views[key]


def _learns(trial: Trial) -> bool:
    """Whether the trial's method learns a route (a control does not)."""
    return trial.method is not None and is_memory_method(trial.method)


_guides: dict[str, MemoryGuide] = {}


def _guide(job: ClosedLoopJob, views: LatticeViews) -> MemoryGuide:
    """A route-learning method trained on the config's training routes into the trial's goal
    (their poses the scene cannot show left out; once per process, goal and method)."""
    t, config = job.trial, job.config
    goal = [t.goal_pose.x, t.goal_pose.y, t.goal_pose.heading]
    training = config.training.model_dump(mode="json")
    key = stable_hash([scene_key(config, t.style), config.seed, t.method, t.params, goal, training])
    if key not in _guides:
        assert t.method is not None
        method = registry.create(t.method, **dict(t.params))
        geometry = views.scene.geometry
        seen = []
        for pose in config.training.poses(t.goal_pose):
            try:
                seen.append(View(views.see(pose), geometry))
            except PoseError:
                continue
        _guides[key] = MemoryGuide.trained(method, seen, geometry)
    return _guides[key]


def _homer(job: ClosedLoopJob, seed: int, views: LatticeViews) -> Homer:
    """The trial's homer: a control, a route-learning method trained on the goal's training
    routes, or its method with the goal snapshot rendered and described (once per process,
    goal and method)."""
    t, config = job.trial, job.config
    if t.method is None:
        if t.label == "truth":
            return TruthHomer(t.goal_pose)
        return RandomHomer(np.random.default_rng([seed, 1]))
    if _learns(t):
        return _guide(job, views)
    method = registry.create(t.method, **dict(t.params))
    scene = trial_scene(config, t.style)
    goal = [t.goal_pose.x, t.goal_pose.y, t.goal_pose.heading]
    key = stable_hash([scene_key(config, t.style), config.seed, t.method, t.params, goal])
    if key not in _goals:
        noise = derived_seed(config.seed, "goal", t.goal)
        view = View(scene.render(t.goal_pose, noise), scene.geometry)
        _goals[key] = (view, method.describe(view))
    view, features = _goals[key]
    return MethodHomer(method, features, scene.geometry, t.compass, t.goal_pose.heading, view)


def run_trial(job: ClosedLoopJob, run_dir: Path) -> dict[str, Any]:
    """Run one trial; its record (JSON-ready)."""
    t, config = job.trial, job.config
    seed = derived_seed(config.seed, t.name)
    views = _lattice_views(config, t.style, run_dir)
    homer = _homer(job, seed, views)
    robot = Robot.at(t.start.pose, config.drift, np.random.default_rng([seed, 0]))
    result = run_loop(robot, t.goal_pose, homer, views.see, views.scene.check_pose, config.motion)
    distance = math.dist(t.start.pose.xy, t.goal_pose.xy)
    final = math.dist(result.poses[-1].xy, t.goal_pose.xy)
    looks = max(result.steps + (result.outcome == "no_estimate"), 1)
    summary = {
        "style": t.style,
        "method": t.label,
        "goal": t.goal,
        "goal_x": t.goal_pose.x,
        "goal_y": t.goal_pose.y,
        "start": t.start.index,
        "start_x": t.start.x,
        "start_y": t.start.y,
        "start_heading_deg": math.degrees(t.start.heading),
        "cell_i": -1 if t.start.cell is None else t.start.cell[0],
        "cell_j": -1 if t.start.cell is None else t.start.cell[1],
        "cell_area_m2": t.start.area,
        "start_distance_m": distance,
        "outcome": result.outcome,
        "success": result.outcome == "success",
        "final_distance_m": final,
        "path_m": result.path,
        "path_ratio": result.path / (distance - config.motion.success_radius),
        "steps": result.steps,
        "no_estimates": result.no_estimates,
        "time_s": result.see_s + result.home_s,
        "see_s_per_step": result.see_s / looks,
        "home_s_per_step": result.home_s / looks,
    }
    return {
        "format": CLOSED_LOOP_FORMAT,
        "trial": t.name,
        "summary": summary,
        "trajectory": [[p.x, p.y, p.heading] for p in result.poses],
    }


def _run_and_write(job: ClosedLoopJob, run_dir: Path) -> None:
    record = {"key": job.key, **run_trial(job, run_dir)}
    path = job.result_path(run_dir)
    make_folder(path.parent)
    write_text_atomic(path, json.dumps(record, allow_nan=False) + "\n")


def run_closed_loop_job(job: ClosedLoopJob, run_dir: Path) -> JobOutcome:
    """Run one trial in a worker and write its file; failures come back in the outcome."""
    return run_safely("closed-loop", job.key, _run_and_write, job, run_dir)


def read_records(plan: list[ClosedLoopJob], run_dir: Path) -> list[dict[str, Any] | None]:
    """Each planned trial's record, None where its file is missing, of another key or does
    not fit the schema."""
    return [job.record(run_dir) for job in plan]


def run_closed_loop_experiment(
    config: ClosedLoopConfig,
    config_path: Path,
    jobs: int | None = None,
    force: bool = False,
    show_progress: bool = True,
) -> TrialRunOutcome:
    """Run every unfinished trial of ``config`` and write the tables; a trial running
    longer than the config's ``job_timeout_s`` fails."""
    forget_databases()  # read as they are now: an edited database gives other keys
    try:
        plan = [ClosedLoopJob(config, trial) for trial in plan_trials(config)]
    except ConfigError as error:
        raise ConfigError(f"{config_path}: {error}") from None
    if not plan:
        raise ConfigError(f"{config_path}: no start lies in free space far enough from a goal")
    with robot_run_folder(config, config_path, CLOSED_LOOP_RESULTS, force) as run_dir:
        return _run_closed_loop_trials(config, plan, run_dir, jobs, force, show_progress)


def _run_closed_loop_trials(
    config: ClosedLoopConfig,
    plan: list[ClosedLoopJob],
    run_dir: Path,
    jobs: int | None,
    force: bool,
    show_progress: bool,
) -> TrialRunOutcome:
    """The trials of a closed-loop run in its claimed ``run_dir``, and its tables."""
    if force:
        for job in plan:
            job.result_path(run_dir).unlink(missing_ok=True)
    todo = [job for job in plan if job.record(run_dir) is None]
    n_jobs = jobs if jobs is not None else config.jobs
    preload = preload_for(config.methods)
    outcomes = run_parallel(
        run_closed_loop_job, todo, run_dir, n_jobs, "trials", show_progress, preload,
        config.job_timeout_s, len(plan) - len(todo),
    )  # fmt: skip
    records = [r for r in read_records(plan, run_dir) if r is not None]
    summary = write_tables(records, config, run_dir / TABLES_DIR)
    failures = tuple(outcome for outcome in outcomes if outcome.error)
    return TrialRunOutcome(
        run_dir,
        summary,
        run_dir / TABLES_DIR / "summary.csv",
        len(todo) - len(failures),
        len(plan) - len(todo),
        failures,
    )
