"""What a worker does: run one describe or home job and write its file atomically.

Workers pin OpenCV to one thread (parallelism comes from the job level), time every describe
and home call themselves, and never raise: a failure comes back as a :class:`JobOutcome` with
the error text, so the run finishes the other jobs and reports it.
"""

from __future__ import annotations

import json
import pickle
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from homebench.errors import DataError
from homebench.evaluation.metrics import angular_errors
from homebench.evaluation.plan import DescribeJob, HomeJob, ImageTask, MethodSpec
from homebench.evaluation.routes import grid_route
from homebench.evaluation.sources import load_view, open_source
from homebench.fileio import read_json_record, write_bytes_atomic, write_text_atomic
from homebench.geometry import home_direction

RESULT_FORMAT = 2  # 2: records carry the swept world seed


@dataclass(frozen=True)
class JobOutcome:
    kind: str  # "describe" or "home"
    key: str
    error: str | None = None


def run_safely(kind: str, key: str, work: Any, *args: Any) -> JobOutcome:
    """Call ``work(*args)`` with OpenCV on one thread; an exception becomes the outcome's error."""
    cv2.setNumThreads(1)
    try:
        work(*args)
    except Exception as error:  # reported per job; the run goes on with the others
        detail = "".join(traceback.format_exception_only(type(error), error)).strip()
        return JobOutcome(kind, key, detail)
    return JobOutcome(kind, key)


def run_describe_job(job: DescribeJob, run_dir: Path) -> JobOutcome:
    return run_safely("describe", job.key, _describe, job, run_dir)


def run_home_job(job: HomeJob, run_dir: Path) -> JobOutcome:
    return run_safely("home", job.key, _home, job, run_dir)


def _describe(job: DescribeJob, run_dir: Path) -> None:
    method = job.method.create()
    for task in job.images:
        path = task.feature_path(run_dir, job.method)
        if path.is_file():
            continue
        view = load_view(task.source, task.i, task.j, job.method.image_kind, task.rotation)
        start = time.perf_counter()
        features = method.describe(view)
        seconds = time.perf_counter() - start
        path.parent.mkdir(parents=True, exist_ok=True)
        payload = {"features": features, "describe_ms": 1000.0 * seconds}
        write_bytes_atomic(path, pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL))


def load_features(task: ImageTask, run_dir: Path, method: MethodSpec) -> dict[str, Any]:
    path = task.feature_path(run_dir, method)
    try:
        with open(path, "rb") as f:
            return pickle.load(f)
    except FileNotFoundError:
        raise DataError(f"{path}: features missing (its describe job did not finish)") from None
    except (pickle.UnpicklingError, EOFError) as error:
        raise DataError(f"{path}: corrupt feature file ({error})") from None


class _RouteViews:
    """Features of the grid views between goal and current, for methods that track along a
    route (``uses_route``). Route views come from the current database (the robot's world) at
    its stored headings; each is described once per job."""

    def __init__(self, job: HomeJob, method: Any):
        self.job, self.method = job, method
        self.source = job.currents[0].source
        self.step = float(getattr(method, "route_step", 0.0))
        self.cache: dict[tuple[int, int], Any] = {}

    def features(self, task: ImageTask) -> list[Any]:
        kind = self.job.method.image_kind
        route = grid_route(
            self.source.grid, (self.job.goal.i, self.job.goal.j), (task.i, task.j), self.step
        )
        for node in route:
            if node not in self.cache:
                self.cache[node] = self.method.describe(load_view(self.source, *node, kind))
        return [self.cache[node] for node in route]


def _home(job: HomeJob, run_dir: Path) -> None:
    method = job.method.create()
    goal = load_features(job.goal, run_dir, job.method)
    current_db, goal_db = open_source(job.currents[0].source), open_source(job.goal.source)
    goal_xy = goal_db.grid.position(job.goal.i, job.goal.j)
    routes = _RouteViews(job, method) if getattr(method, "uses_route", False) else None
    rows = []
    for task in job.currents:
        current = load_features(task, run_dir, job.method)
        route = {"route": routes.features(task)} if routes is not None else {}
        start = time.perf_counter()
        estimate = method.home(current["features"], goal["features"], **route)
        home_ms = 1000.0 * (time.perf_counter() - start)
        heading = current_db.heading(task.i, task.j) + task.rotation
        current_xy = current_db.grid.position(task.i, task.j)
        angle = np.nan if estimate.angle is None else float(estimate.angle)
        estimate_world = heading + angle
        rows.append(
            {
                "current_i": task.i,
                "current_j": task.j,
                "rotation": task.rotation,
                "heading": heading,
                "estimate": None if estimate.angle is None else angle,
                "estimate_world": None if estimate.angle is None else float(estimate_world),
                "truth": float(home_direction(current_xy, goal_xy, heading)),
                "ae": _none_if_nan(angular_errors(estimate_world, current_xy, goal_xy)),
                "rotation_estimate": estimate.rotation,
                "distance_m": float(np.hypot(*(goal_xy - current_xy))),
                "n_landmarks": int(estimate.n_landmarks),
                "route_views": len(route.get("route", ())),
                "score": estimate.score,
                "home_ms": home_ms,
                "describe_ms": current["describe_ms"],
                "goal_describe_ms": goal["describe_ms"],
            }
        )
    record = {
        "format": RESULT_FORMAT,
        "key": job.key,
        "seed": job.seed,
        "condition": job.condition,
        "method": job.method.label,
        "method_name": job.method.method,
        "params": dict(job.method.params),
        "current_database": job.currents[0].source.alias,
        "goal_database": job.goal.source.alias,
        "goal_i": job.goal.i,
        "goal_j": job.goal.j,
        "goal_heading": goal_db.heading(job.goal.i, job.goal.j),
        "grid": {
            "shape": list(current_db.grid.shape),
            "spacing": current_db.grid.spacing,
            "origin": list(current_db.grid.origin),
        },
        "rows": rows,
    }
    path = job.result_path(run_dir)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(record, indent=1, default=_json_default))


def _none_if_nan(value: Any) -> float | None:
    value = float(np.asarray(value))
    return None if np.isnan(value) else value


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot write a {type(value).__name__} to a result file")


def read_result(path: Path, key: str) -> dict[str, Any] | None:
    """A finished job's record, or None if the file is missing, corrupt, of another job or of an
    older result format."""
    record = read_json_record(path, key)
    return record if record is not None and record.get("format") == RESULT_FORMAT else None
