"""The trial files of the robot experiments (route, closed loop): what a run did and reading one.

A trial is one JSON file written atomically, holding the ``key`` of everything that decided it;
a file whose key differs is of another configuration (or code) and is not reused or reported,
nor is one that does not fit its experiment's schema (a :class:`TrialRecord`: the types of
what the tables and the report read, and a summary that names the trial it belongs to). A run
computes such a trial again; a report lists it as missing.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar

import pandas as pd
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from homebench.evaluation.claims_record import with_stamped_claims
from homebench.evaluation.jobs import JobOutcome
from homebench.evaluation.run_folder import check_owner, claim_run_folder, lock_run_folder
from homebench.evaluation.runner import write_run_metadata
from homebench.fileio import parse_json, read_record_text

#: Poses as a trial file holds them: (n, 3) rows (x [m], y [m], heading [rad]).
Poses = list[Annotated[list[float], Field(min_length=3, max_length=3)]]


class TrialRecord(BaseModel):
    """A trial file: its ``key`` (fields its experiment's schema adds are typed there; others
    are left as they are)."""

    model_config = ConfigDict(extra="allow", strict=True)

    key: str


@dataclass(frozen=True)
class TrialRunOutcome:
    """What a robot experiment's run did, for the CLI: the summary ``table`` (written to
    ``table_path``), trials ``computed`` now and ``reused``, the ``failures`` of the trials
    run now, and ``notes`` for the user on what the config implies (one line each)."""

    run_dir: Path
    table: pd.DataFrame
    table_path: Path
    computed: int
    reused: int
    failures: tuple[JobOutcome, ...]
    notes: tuple[str, ...] = ()


@contextlib.contextmanager
def robot_run_folder(config: Any, config_path: Path, results: str, force: bool) -> Iterator[Path]:
    """The run folder of a robot experiment's ``config`` (its ``output``), as grid runs hold
    theirs (:mod:`homebench.evaluation.run_folder`): locked while the run uses it (a second
    run into it is refused), belonging to one config (a run of another config there, of any
    kind, is refused unless ``force``), its ``config.resolved.json`` (the claims stamped
    before any trial runs, counting the files ``results`` matches) and ``environment.json``
    written before the trials."""
    run_dir = Path(config.output)
    with lock_run_folder(run_dir):
        with claim_run_folder(run_dir):
            resolved = config.model_dump(mode="json")
            resolved = with_stamped_claims(resolved, config.claims, run_dir, results)
            check_owner(run_dir, resolved, force, can_update=False)
            write_run_metadata(config, config_path, run_dir, resolved)
        yield run_dir


def read_trial(
    path: Path,
    run_dir: Path,
    trial: str,
    key: str,
    schema: type[TrialRecord],
    names: Mapping[str, Any],
) -> dict[str, Any] | str:
    """The record of ``trial`` at ``path``: a JSON object with the trial's ``key`` that fits
    ``schema`` and whose summary holds ``names`` (column -> value: the trial it is of); or
    why there is none: "routes/x.json (trial x: missing)", "(trial x: corrupt, summary.steps:
    Input should be a valid integer)"."""
    where = f"{path.relative_to(run_dir).as_posix()} (trial {trial}"
    try:
        record = parse_json(read_record_text(path))
    except FileNotFoundError:
        return f"{where}: missing)"
    except (OSError, ValueError) as error:
        return f"{where}: corrupt, {error})"
    if not isinstance(record, dict):
        return f"{where}: corrupt, not a JSON object)"
    if record.get("key") != key:
        return f"{where}: of another configuration, key {record.get('key')} != {key})"
    try:
        schema.model_validate(record)
    except ValidationError as error:
        first = error.errors()[0]
        field = ".".join(str(part) for part in first["loc"])
        return f"{where}: corrupt, {field}: {first['msg']})"
    other = next((name for name, value in names.items() if record["summary"][name] != value), None)
    if other is not None:
        return f"{where}: corrupt, summary.{other} {record['summary'][other]!r} is another trial's)"
    return record


class TrialFile:
    """What a robot experiment's job reads of its trial file; the job class gives the
    ``schema`` of its files, ``key``, ``trial`` (with its ``name``), ``result_path(run_dir)``
    and ``names()``, the summary columns that say which trial a file is of."""

    schema: ClassVar[type[TrialRecord]]
    key: str
    trial: Any

    def result_path(self, run_dir: Path) -> Path: ...

    def names(self) -> dict[str, Any]: ...

    def read(self, run_dir: Path) -> dict[str, Any] | str:
        """The trial's record in ``run_dir``, or why there is none (:func:`read_trial`)."""
        path = self.result_path(run_dir)
        return read_trial(path, run_dir, self.trial.name, self.key, self.schema, self.names())

    def record(self, run_dir: Path) -> dict[str, Any] | None:
        """The trial's record in ``run_dir``; None where there is none: a run computes it."""
        record = self.read(run_dir)
        return None if isinstance(record, str) else record
