"""The trial files of the robot experiments (route, closed loop): what a run did and reading one.

A trial is one JSON file written atomically, holding the ``key`` of everything that decided it;
a file whose key differs is of another configuration (or code) and is not reused or reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from homebench.evaluation.jobs import JobOutcome
from homebench.fileio import parse_json, read_record_text


@dataclass(frozen=True)
class TrialRunOutcome:
    """What a robot experiment's run did, for the CLI: the summary ``table`` (written to
    ``table_path``), trials ``computed`` now and ``reused``, and the ``failures``."""

    run_dir: Path
    table: pd.DataFrame
    table_path: Path
    computed: int
    reused: int
    failures: tuple[JobOutcome, ...]


def read_trial(path: Path, run_dir: Path, trial: str, key: str) -> dict[str, Any] | str:
    """The record of ``trial`` at ``path`` (a JSON object with a ``summary`` object and the
    trial's ``key``), or why there is none: "routes/x.json (trial x: missing)"."""
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
    if not isinstance(record.get("summary"), dict):
        return f"{where}: corrupt, no summary)"
    return record
