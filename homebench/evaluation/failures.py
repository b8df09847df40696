"""Failed jobs, recorded in the run folder: ``failures/<job key>.json``.

A job that raised, crashed, timed out or ran out of memory leaves a record with its cause and
the number of attempts. A plain rerun does not run it again (a crash is usually deterministic,
and a rerun should not repeat minutes of timeouts): it is reported as failed, and only ``homebench
run --retry-failed`` retries it. A job that succeeds loses its record. Keys hold the method's
code version, so a fixed method gets new keys and runs without ``--retry-failed``.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from pathlib import Path

from homebench.evaluation.records import FAILURE, read_record
from homebench.fileio import make_folder, write_text_atomic

FAILURES_DIR = "failures"


@dataclass(frozen=True)
class Failure:
    """A failed job: its ``kind`` and ``key``, what it is (``job``: method, condition, goal, or
    the images of a describe job), the ``cause`` of its last attempt, and ``attempts``."""

    kind: str
    key: str
    job: str
    cause: str
    attempts: int


def failure_path(run_dir: Path, key: str) -> Path:
    return Path(run_dir) / FAILURES_DIR / f"{key}.json"


def read_failure(run_dir: Path, key: str) -> Failure | None:
    """The failure record of job ``key``, or None (no record, or one that is unreadable or
    does not fit its schema)."""
    record = read_record(FAILURE, failure_path(run_dir, key), key)
    if record is None:
        return None
    return Failure(**{name: record[name] for name in Failure.__dataclass_fields__})


def record_failure(run_dir: Path, kind: str, key: str, job: str, cause: str) -> Failure:
    """Record (another) failed attempt of job ``key``; the updated record."""
    previous = read_failure(run_dir, key)
    failure = Failure(kind, key, job, cause, 1 + (previous.attempts if previous else 0))
    record = {**asdict(failure), "time": datetime.now(UTC).isoformat(timespec="seconds")}
    path = failure_path(run_dir, key)
    make_folder(path.parent)
    write_text_atomic(path, json.dumps(record, indent=1) + "\n")
    return failure


def clear_failure(run_dir: Path, key: str) -> None:
    """Forget a job's failures (it succeeded, or is to be recomputed from scratch)."""
    failure_path(run_dir, key).unlink(missing_ok=True)
