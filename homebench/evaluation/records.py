"""The schemas of the records a run writes and reads back: job results, the plan, failures.

A run folder may come from anyone, so what is read from it is validated before anything uses
it, strictly (a number must be a JSON number, an index an integer inside the grid): a job
record that does not fit is no result (its job is computed again, readers list it as missing);
a failure record that does not fit is no record; a plan that does not fit is an error naming
it. Records are ``TypedDict``\\ s, validated straight from their JSON text: they stay plain
dicts, as fast to tabulate as before.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal, NotRequired, TypeVar

from pydantic import ConfigDict, Field, TypeAdapter, ValidationError, with_config
from typing_extensions import TypedDict  # pydantic needs it for TypedDicts before Python 3.12

from homebench.fileio import read_record_text

#: 2: the swept world seed; 3: rows carry an "error"; 4: the swept style; 5: the databases'
#: identities and whether the method gives a home direction.
RESULT_FORMAT = 5

_STRICT = ConfigDict(strict=True, extra="forbid")
Index = Annotated[int, Field(ge=0)]
#: A job's key (a hex digest), also its file's name: never a path.
Key = Annotated[str, Field(pattern=r"^[0-9A-Za-z_-]{1,128}$")]


@with_config(_STRICT)
class PairRow(TypedDict):
    """One pair of a home job, in the columns' order; times are null where none was taken (a
    process's first call), a failed pair has its ``error`` and no answer."""

    current_i: Index
    current_j: Index
    rotation: float
    heading: float
    estimate: float | None
    estimate_world: float | None
    truth: float
    ae: float | None
    rotation_estimate: float | None
    distance_m: float
    n_landmarks: int | None
    route_views: int | None
    score: float | None
    home_ms: float | None
    describe_ms: float | None
    goal_describe_ms: float | None
    error: str | None


#: The columns of a pair's row, in order.
ROW_COLUMNS = tuple(PairRow.__annotations__)


Finite = Annotated[float, Field(allow_inf_nan=False)]


@with_config(_STRICT)
class GridRecord(TypedDict):
    """The current database's grid; posed places (:class:`~homebench.geometry.Places`) add
    ``places``: their positions (n, 2) in metres, the shape being (n, 1); a grid with holes
    (:class:`~homebench.geometry.HoledGrid`) ``missing``: the positions (i, j) without an
    image."""

    shape: tuple[Annotated[int, Field(ge=1)], Annotated[int, Field(ge=1)]]
    spacing: Annotated[float, Field(gt=0, allow_inf_nan=False)]
    origin: tuple[float, float]
    places: NotRequired[list[tuple[Finite, Finite]]]
    missing: NotRequired[list[tuple[Index, Index]]]


@with_config(_STRICT)
class JobRecord(TypedDict):
    """A home job's result file (format :data:`RESULT_FORMAT`), written by
    :func:`homebench.evaluation.jobs.run_home_job`."""

    format: Literal[5]
    key: Key
    style: str | None
    seed: int | None
    condition: str
    method: str
    method_name: str
    params: dict[str, Any]
    compass: str
    code_version: str
    current_database: str
    goal_database: str
    current_database_key: str
    goal_database_key: str
    gives_direction: bool
    goal_i: Index
    goal_j: Index
    goal_heading: float
    grid: GridRecord
    rows: list[PairRow]


@with_config(_STRICT)
class PlanEntry(TypedDict):
    """A home job of ``plan.json``: its key and what it is."""

    key: Key
    condition: str
    method: str
    goal: tuple[Index, Index]


@with_config(_STRICT)
class FailureRecord(TypedDict):
    """A failed job's record in ``failures/``."""

    kind: str
    key: Key
    job: str
    cause: str
    attempts: Annotated[int, Field(ge=1)]
    time: NotRequired[str]


_JOB = TypeAdapter(JobRecord)
PLAN = TypeAdapter(list[PlanEntry])
FAILURE = TypeAdapter(FailureRecord)
R = TypeVar("R", JobRecord, FailureRecord)


def first_problem(error: ValidationError) -> str:
    """The first problem of a failed validation in words, with its key: "0.key: String should
    match pattern ..."."""
    problem = error.errors()[0]
    where = ".".join(str(part) for part in problem["loc"])
    return f"{where}: {problem['msg']}" if where else problem["msg"]


def read_record(adapter: TypeAdapter[R], path: Path, key: str) -> R | None:
    """The record of ``key`` in the JSON file ``path``, validated by ``adapter``; None if the
    file is missing, unreadable, too large, of another key or does not fit."""
    try:
        record = adapter.validate_json(read_record_text(path))
    except (OSError, ValueError):  # a ValidationError is a ValueError
        return None
    return record if record["key"] == key else None


def read_job_record(path: Path, key: str) -> JobRecord | None:
    """The result record of job ``key`` in ``path`` if it fits :class:`JobRecord`, its goal
    and pairs lie in its grid and not on a position it misses, its places (if any) are as
    many as the grid's shape says and its missing positions (if any) lie in it, some left;
    None otherwise."""
    job = read_record(_JOB, path, key)
    if job is None:
        return None
    nx, ny = job["grid"]["shape"]
    if "places" in job["grid"] and (ny != 1 or len(job["grid"]["places"]) != nx):
        return None
    missing = {(i, j) for i, j in job["grid"].get("missing", ())}
    positions = [(job["goal_i"], job["goal_j"])]
    positions += [(row["current_i"], row["current_j"]) for row in job["rows"]]
    inside = all(i < nx and j < ny for i, j in [*positions, *missing])
    fits = inside and len(missing) < nx * ny and missing.isdisjoint(positions)
    return job if fits else None
