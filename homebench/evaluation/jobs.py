"""What a worker does: run one describe or home job and write its file atomically.

Workers pin OpenCV to one thread (parallelism comes from the job level), time every describe
and home call themselves, and never raise: a failure comes back as a :class:`JobOutcome` with
the error text, so the run finishes the other jobs and reports it. Within a job, one image or
one pair that fails does not sink the others: a describe job describes the rest and then fails
naming the images; a home job records the pair as a row with an ``error`` and no estimate.
A home job prepares its pairs (features, the views beyond the two, the compass's turn) and homes
them: all in one batch call where the method has one, else each as soon as it is prepared
(:mod:`~homebench.evaluation.pair_calls`, which also says what the times are). Feature files
(:mod:`~homebench.evaluation.features_io`) are checked before they are reused.

A method entry's ``compass``
(:data:`~homebench.methods.image_difference.visual_compass.CompassMode`) is applied
here, for any method: with ``visual`` or ``truth`` the current view (and the grid neighbours of
methods that read them) is turned back by the compass's heading change before the method
describes it, and the answer is turned into the current robot frame; ``rotation_estimate`` is
then the compass's turn plus the method's own rotation, and ``ae`` the error of that answer.
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import orjson

from homebench.analysis.metrics import angular_errors
from homebench.data.database import GridDatabase
from homebench.errors import DataError, WriteError
from homebench.evaluation.features_io import StoredFeatures, load_features, save_features
from homebench.evaluation.grid_routes import method_route
from homebench.evaluation.pair_calls import (
    Answer,
    PairInput,
    describe_error,
    home_pairs,
    timed,
)
from homebench.evaluation.plan import (
    DescribeJob,
    HomeJob,
    ImageInputs,
    ImageTask,
    described,
    neighbour_positions,
)
from homebench.evaluation.records import RESULT_FORMAT, ROW_COLUMNS, JobRecord, read_job_record
from homebench.evaluation.sources import load_view, open_source
from homebench.fileio import make_folder, write_bytes_atomic
from homebench.geometry import Grid, Places, home_direction, missing_positions, world_to_robot_xy
from homebench.methods.base import batch_home, gives_direction
from homebench.methods.image_difference.visual_compass import (
    compass_turn,
    in_current_frame,
    whole_columns,
)


@dataclass(frozen=True)
class JobOutcome:
    """What a job did: its ``error`` (None: it succeeded); ``environment`` when that error is
    a file it could not write (a full disk): no failure of the job, it stops the run."""

    kind: str  # "describe", "home" or a robot experiment's trials
    key: str
    error: str | None = None
    environment: bool = False


def run_safely(kind: str, key: str, work: Any, *args: Any) -> JobOutcome:
    """Call ``work(*args)`` with OpenCV on one thread; an exception becomes the outcome's error
    (a WriteError the environment's)."""
    cv2.setNumThreads(1)
    try:
        work(*args)
    except WriteError as error:  # the disk's fault: the run stops, the job has not failed
        return JobOutcome(kind, key, str(error), environment=True)
    except Exception as error:  # reported per job; the run goes on with the others
        return JobOutcome(kind, key, describe_error(error))
    return JobOutcome(kind, key)


def run_describe_job(job: DescribeJob, run_dir: Path) -> JobOutcome:
    return run_safely("describe", job.key, _describe, job, run_dir)


def run_home_job(job: HomeJob, run_dir: Path) -> JobOutcome:
    return run_safely("home", job.key, _home, job, run_dir)


def _has_features(path: Path, key: str) -> bool:
    """Whether ``path`` holds usable features of ``key`` (a missing, corrupt or stale file,
    made from other inputs, does not: its image is described again)."""
    try:
        load_features(path, key, from_disk=True)
    except DataError:
        return False
    return True


def _describe(job: DescribeJob, run_dir: Path) -> None:
    """Describe every image whose feature file is missing or unusable; then DataError naming
    the images that failed, if any (a file that cannot be written stops the job at once)."""
    method = job.method.create()
    failed = []
    for task in job.images:
        path, key = _feature_file(task.inputs, run_dir, job.method.key)
        if _has_features(path, key):
            continue
        try:
            view = load_view(task.source, task.i, task.j, job.method.image_kind, task.rotation)
            features, ms = timed(job.method.key, "describe", lambda v=view: method.describe(v))
            save_features(path, key, features, ms)
        except WriteError:
            raise
        except Exception as error:  # the batch's other images go on
            failed.append(f"({task.i}, {task.j}): {describe_error(error)}")
    if failed:
        raise DataError(f"describe failed for {len(failed)} image(s): {'; '.join(failed)}")


#: Feature files whose path and key a process remembers (a few hundred bytes each).
FEATURE_FILES_REMEMBERED = 16384


@functools.lru_cache(maxsize=FEATURE_FILES_REMEMBERED)
def _feature_file(image: ImageInputs, run_dir: Path, method_key: str) -> tuple[Path, str]:
    """The path and key of the feature file of the image of ``image`` inputs in ``run_dir`` by
    the method of key ``method_key``, remembered: a run's home jobs ask for every current
    view's once per goal, and hashing the key and joining the path each time cost a warping
    pair a tenth of its time."""
    return image.feature_path(run_dir, method_key), image.feature_key(method_key)


def _features(task: ImageTask, run_dir: Path, job: HomeJob) -> StoredFeatures:
    return load_features(*_feature_file(task.inputs, run_dir, job.method.key))


class _GridViews:
    """Features of more grid views than the pair's two, described once per job, from the
    current database (the robot's world) at its stored headings: the views along the route
    from the goal for methods that track (``uses_route``, see
    :func:`~homebench.evaluation.grid_routes.method_route`), the grid neighbours of the
    current view for methods that sample around it (``uses_neighbours``, their
    ``neighbour_step``). A view that is one of the job's described current views is read
    from its feature file (with ``run_dir``) instead of being described again: a route view
    then comes with its ``describe`` features, not its ``describe_route`` ones, so a method's
    ``home`` must read of a route view only what both hold (klt-sector: the image and its
    digest)."""

    def __init__(self, job: HomeJob, method: Any, run_dir: Path | None = None):
        self.job, self.method, self.run_dir = job, method, run_dir
        self.source = job.currents[0].source
        self.grid = self.source.grid
        self.cache: dict[tuple[int, int, float, bool], Any] = {}

    @functools.cached_property  # built when a method first asks for a view beyond the pair
    def stored(self) -> dict[tuple[int, int, float], ImageTask]:
        """The job's described current views, by (i, j, rotation)."""
        currents = set(self.job.currents)
        return {(t.i, t.j, t.rotation): t for t in described(self.job) if t in currents}

    def _describe(self, i: int, j: int, rotation: float = 0.0, route: bool = False) -> Any:
        """Features of a view: stored, or described (a route view's by the method's
        ``describe_route`` if it has one: a tracker needs the image, not the view's own
        corners)."""
        key = (i, j, rotation, route)
        if key not in self.cache:
            features = self._stored(i, j, rotation)
            if features is None:
                view = load_view(self.source, i, j, self.job.method.image_kind, rotation)
                describe = getattr(self.method, "describe_route", None) if route else None
                features = (describe or self.method.describe)(view)
            self.cache[key] = features
        return self.cache[key]

    def _stored(self, i: int, j: int, rotation: float) -> Any:
        """The stored features of the view, if it is a described current view; else None."""
        task = self.stored.get((i, j, rotation))
        if task is None or self.run_dir is None:
            return None
        try:
            return _features(task, self.run_dir, self.job).features
        except DataError:  # a missing or unusable file: described here instead
            return None

    def extra(self, task: ImageTask, heading: float) -> dict[str, list[Any]]:
        """The keyword arguments of ``home`` beyond the two views (none for most methods)."""
        found: dict[str, list[Any]] = {}
        if getattr(self.method, "uses_route", False):
            found["route"] = self.route(task)
        if getattr(self.method, "uses_neighbours", False):
            found["neighbours"] = self.neighbours(task, heading)
        return found

    def route(self, task: ImageTask) -> list[Any]:
        """Features of the views between the goal and ``task`` (both excluded), goal first."""
        goal = (self.job.goal.i, self.job.goal.j)
        route = method_route(self.method, self.grid, goal, (task.i, task.j))
        return [self._describe(*node, route=True) for node in route]

    def neighbours(self, task: ImageTask, heading: float) -> list[tuple[np.ndarray, Any]]:
        """(offset, features) of the views ``neighbour_step`` grid units from ``task`` along
        each grid axis, those inside the grid: the offset (2,) in metres in the current robot
        frame (``heading``: the current view's, radians), the view turned by the task's
        rotation like the current one."""
        step = int(getattr(self.method, "neighbour_step", 1))
        here = self.grid.position(task.i, task.j)
        return [
            (
                world_to_robot_xy(self.grid.position(i, j) - here, heading),
                self._describe(i, j, task.rotation),
            )
            for i, j in neighbour_positions(self.grid, task.i, task.j, step)
        ]


class _Compass:
    """The entry's compass step for the pairs of one job: the heading change (radians, whole
    columns of the current database's unfolded views) to turn each current view back by, or
    None with ``compass = none``. ``visual``: the visual compass on the two unfolded views
    (the goal's read once per job); ``truth``: the current view's heading minus the goal's."""

    def __init__(self, job: HomeJob, goal_heading: float):
        self.job, self.goal_heading = job, goal_heading
        self.goal_view: Any = None

    def turn(self, task: ImageTask, heading: float) -> float | None:
        mode = self.job.method.compass
        if mode == "none":
            return None
        if mode == "truth":
            return whole_columns(heading - self.goal_heading, task.source.columns)
        goal = self.job.goal
        if self.goal_view is None:
            self.goal_view = load_view(goal.source, goal.i, goal.j, "unfolded")
        current = load_view(task.source, task.i, task.j, "unfolded", task.rotation)
        return compass_turn(current, self.goal_view)


def _current_features(
    job: HomeJob, run_dir: Path, method: Any, task: ImageTask, fresh: bool
) -> tuple[Any, float]:
    """Features of a current view and their describe time (ms): from its feature file, or,
    when ``fresh`` (a view turned back by a compass), described now."""
    if not fresh:
        stored = _features(task, run_dir, job)
        return stored.features, stored.describe_ms
    view = load_view(task.source, task.i, task.j, job.method.image_kind, task.rotation)
    return timed(job.method.key, "describe", lambda: method.describe(view))


@dataclass(frozen=True)
class _Prepared:
    """A pair ready for its home call: its index ``k`` in the job, the compass's ``turn``
    (radians; None without a compass), the current's ``describe_ms`` and the call's input."""

    k: int
    turn: float | None
    describe_ms: float
    call: PairInput


def _prepare(
    job: HomeJob,
    run_dir: Path,
    k: int,
    heading: float,
    parts: tuple[Any, _GridViews, _Compass],
) -> _Prepared:
    """Pair ``k`` ready for its home call: with a compass, the method sees the current view
    (and its neighbours) turned back."""
    method, views, compass = parts
    task = job.currents[k]
    turn = compass.turn(task, heading)
    seen = task if turn is None else replace(task, rotation=task.rotation - turn)
    features, describe_ms = _current_features(job, run_dir, method, seen, turn is not None)
    extra = views.extra(seen, heading - (turn or 0.0))
    return _Prepared(k, turn, describe_ms, PairInput(features, extra))


def _answer(pair: _Prepared, answer: Answer, heading: float, goal_ms: float) -> dict[str, Any]:
    """A pair's row fields of its ``answer`` (estimate or error, home time in ms), in the
    current robot frame (with a compass, the pair's turn turns the method's answer into it);
    ``heading``: the current's world heading (radians); ``goal_ms``: the goal's describe time."""
    estimate, home_ms = answer
    if isinstance(estimate, str):  # the error its call raised
        return {"error": estimate}
    try:
        if pair.turn is not None:
            estimate = in_current_frame(estimate, pair.turn)
        angle = None if estimate.angle is None else float(estimate.angle)
        fields = {
            "estimate": angle,
            "estimate_world": None if angle is None else heading + angle,
            "rotation_estimate": estimate.rotation,
            "n_landmarks": int(estimate.n_landmarks),
            "score": estimate.score,
        }
    except Exception as error:  # an answer that is no number: this pair fails
        return {"error": describe_error(error)}
    return fields | {
        "route_views": len(pair.call.extra.get("route", ())),
        "home_ms": home_ms,
        "describe_ms": pair.describe_ms,
        "goal_describe_ms": goal_ms,
    }


def _pair_rows(
    job: HomeJob,
    run_dir: Path,
    method: Any,
    databases: tuple[GridDatabase, GridDatabase],
    goal_heading: float,
) -> list[dict]:
    """The rows of the job's pairs (:data:`ROW_COLUMNS`), their answers in the current robot
    frame: the pairs prepared, then homed (:func:`~.pair_calls.home_pairs`; all in one batch
    call where the method has one); a pair that fails keeps its row with its ``error``.
    ``databases``: the current and goal databases."""
    goal = _features(job.goal, run_dir, job)
    current_db, goal_db = databases
    goal_xy = goal_db.grid.position(job.goal.i, job.goal.j)
    parts = (method, _GridViews(job, method, run_dir), _Compass(job, goal_heading))
    # the pairs' geometry at once: headings (n,), positions (n, 2), true directions (n,)
    headings = [current_db.heading(task.i, task.j) + task.rotation for task in job.currents]
    current_xy = current_db.grid.position(
        [task.i for task in job.currents], [task.j for task in job.currents]
    )
    truths = home_direction(current_xy, goal_xy, np.asarray(headings, dtype=np.float64))
    distances = np.hypot(*(goal_xy - current_xy).T)
    # a method with a batch call homes the job's pairs at once; others each pair once prepared,
    # so that a job holds one pair's features at a time, as before batch calls
    batched, rows, pending = batch_home(method) is not None, [], []
    for k, (task, truth, distance) in enumerate(
        zip(job.currents, truths.tolist(), distances.tolist(), strict=True)
    ):
        row = dict.fromkeys(ROW_COLUMNS)  # in the columns' order; a failed pair keeps Nones
        row.update(
            current_i=task.i,
            current_j=task.j,
            rotation=task.rotation,
            heading=headings[k],
            truth=truth,
            distance_m=distance,
        )
        rows.append(row)
        try:
            pending.append(_prepare(job, run_dir, k, headings[k], parts))
        except Exception as error:  # one failed pair; the job's other pairs go on
            row["error"] = describe_error(error)
        if pending and (not batched or k == len(job.currents) - 1):
            answers = home_pairs(job.method.key, method, goal.features, [p.call for p in pending])
            for pair, answer in zip(pending, answers, strict=True):
                rows[pair.k].update(_answer(pair, answer, headings[pair.k], goal.describe_ms))
            pending = []
    estimates_world = [np.nan if r["estimate_world"] is None else r["estimate_world"] for r in rows]
    errors = angular_errors(np.array(estimates_world), current_xy, goal_xy).tolist()
    for row, ae in zip(rows, errors, strict=True):
        if row["error"] is None:
            row["ae"] = None if math.isnan(ae) else ae
    return rows


def _home(job: HomeJob, run_dir: Path) -> None:
    method = job.method.create()
    current_db, goal_db = open_source(job.currents[0].source), open_source(job.goal.source)
    goal_heading = goal_db.heading(job.goal.i, job.goal.j)
    rows = _pair_rows(job, run_dir, method, (current_db, goal_db), goal_heading)
    record = {
        "format": RESULT_FORMAT,
        "key": job.key,
        "style": job.style,
        "seed": job.seed,
        "condition": job.condition,
        "method": job.method.label,
        "method_name": job.method.method,
        "params": dict(job.method.params),
        "compass": job.method.compass,
        "code_version": job.method.code,
        "current_database": job.currents[0].source.alias,
        "goal_database": job.goal.source.alias,
        "current_database_key": job.currents[0].source.database_key,
        "goal_database_key": job.goal.source.database_key,
        "gives_direction": gives_direction(type(method)),
        "goal_i": job.goal.i,
        "goal_j": job.goal.j,
        "goal_heading": goal_heading,
        "grid": grid_record(current_db.grid),
        "rows": rows,
    }
    path = job.result_path(run_dir)
    make_folder(path.parent)
    write_bytes_atomic(path, _result_json(record))


def grid_record(grid: Grid) -> dict[str, Any]:
    """The ``grid`` of a job record: shape, spacing, origin, and the positions (n, 2) metres
    of posed places (:class:`~homebench.geometry.Places`), so readers can tell them apart, or
    the positions (i, j) a grid with holes misses (:class:`~homebench.geometry.HoledGrid`)."""
    record: dict[str, Any] = {
        "shape": list(grid.shape),
        "spacing": grid.spacing,
        "origin": list(grid.origin),
    }
    if isinstance(grid, Places):
        record["places"] = [list(xy) for xy in grid.xy]
    if missing_positions(grid):
        record["missing"] = [list(ij) for ij in missing_positions(grid)]
    return record


def _result_json(record: dict[str, Any]) -> bytes:
    """The JSON of a result record: by orjson (0.4 us a row where the stdlib takes 5; a warping
    pair takes about 250), which writes NaN as null, as JSON has no NaN; by the stdlib when
    the record holds what orjson cannot write (an integer beyond 64 bits, which a plugin's
    parameter may be), NaN then as NaN."""
    try:
        return orjson.dumps(record, default=_json_default)
    except orjson.JSONEncodeError:
        return json.dumps(record, default=_json_default).encode()


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot write a {type(value).__name__} to a result file")


def read_result(path: Path, key: str) -> JobRecord | None:
    """A finished job's record, or None if the file is missing, corrupt, of another job or of an
    older result format, or does not fit the record's schema (:mod:`.records`)."""
    return read_job_record(path, key)
