"""Several grid runs side by side: their short labels, and what differs in how they were run.

Labels are the run folders' names; where names repeat, each takes as many parent folders as
tell it apart (``x/seed1/run`` beside ``y/seed1/run``). Differences are listed against the
first run, as flat dotted keys: ``methods[0].params.ratio: 0.8 -> 0.7``, from the resolved
configs and from the environments' fields that decide results (homebench version, git commit,
method code versions, database manifest hashes).
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from homebench.errors import ConfigError, DataError
from homebench.report.run_data import RunData, grid_run, read_run_info

#: The environment.json fields compared (flat keys).
ENVIRONMENT_FIELDS = re.compile(
    r"(homebench|versions\.homebench|git\.(commit|dirty)|methods\..+\.code_version"
    r"|databases\..+\.(manifest_sha256|key))"
)
_ABSENT = object()


def load_grid_runs(run_dirs: Sequence[Path]) -> list[RunData]:
    """Each folder's grid run; DataError for a route run or a run without any job result."""
    runs = []
    for run_dir in run_dirs:
        info = read_run_info(Path(run_dir))
        if info.kind != "grid":
            raise DataError(f"{run_dir}: a {info.kind} run; only grid runs can be compared")
        run = grid_run(info)
        if run.tables.summary.empty:
            raise DataError(f"{run_dir}: no job results (run it first)")
        runs.append(run)
    return runs


def missing_results(runs: Sequence[RunData], labels: Sequence[str]) -> list[str]:
    """One line per job of the runs without a valid result: "label: missing jobs/x.json
    (condition, method, goal (i, j))"."""
    return [
        f"{label}: missing {job}"
        for label, run in zip(labels, runs, strict=True)
        for job in run.tables.missing_jobs
    ]


def run_labels(run_dirs: Sequence[Path], labels: Sequence[str] = ()) -> list[str]:
    """A short unique label per run folder: ``labels`` when given (one per folder), else the
    folder's name with as many parent folders as tell repeated names apart."""
    if labels:
        if len(labels) != len(run_dirs):
            raise ConfigError(f"--label: {len(labels)} label(s) for {len(run_dirs)} runs")
        chosen = list(labels)
    else:
        parts = [Path(d).resolve().parts for d in run_dirs]
        depth = [1] * len(parts)
        while True:
            chosen = [Path(*p[-k:]).as_posix() for p, k in zip(parts, depth, strict=True)]
            repeated = [
                i for i, c in enumerate(chosen) if chosen.count(c) > 1 and depth[i] < len(parts[i])
            ]
            if not repeated:
                break
            for i in repeated:
                depth[i] += 1
    twice = sorted({label for label in chosen if chosen.count(label) > 1})
    if twice:
        raise ConfigError(f"run label {twice[0]!r} names two runs; give each a --label")
    return chosen


def flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    """Nested dicts and lists as one dict of dotted keys: ``{"a": [{"b": 1}]}`` ->
    ``{"a[0].b": 1}``; an empty dict or list stays a value."""
    if isinstance(value, dict) and value:
        items = [(f"{prefix}.{k}" if prefix else str(k), v) for k, v in value.items()]
    elif isinstance(value, list) and value:
        items = [(f"{prefix}[{i}]", v) for i, v in enumerate(value)]
    else:
        return {prefix: value}
    return {key: leaf for k, v in items for key, leaf in flatten(v, k).items()}


def differences(reference: dict[str, Any], other: dict[str, Any]) -> list[str]:
    """``key: old -> new`` for every flat key whose value differs (sorted by key)."""
    old, new = flatten(reference), flatten(other)
    return [
        f"{key}: {_shown(old, key)} -> {_shown(new, key)}"
        for key in sorted(old.keys() | new.keys())
        if old.get(key, _ABSENT) != new.get(key, _ABSENT)
    ]


def _shown(flat: dict[str, Any], key: str) -> str:
    return json.dumps(flat[key], sort_keys=True) if key in flat else "(absent)"


def _relevant_environment(environment: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in flatten(environment).items() if ENVIRONMENT_FIELDS.fullmatch(k)}


def run_differences(runs: Sequence[RunData], labels: Sequence[str]) -> list[str]:
    """One line per difference of each run from the first: ``label: config key: a -> b`` and
    ``label: environment key: a -> b``; empty when the runs were run alike."""
    reference = runs[0]
    lines = []
    for run, label in zip(runs[1:], labels[1:], strict=True):
        lines += [f"{label}: config {d}" for d in differences(reference.config, run.config)]
        environments = (_relevant_environment(r.environment) for r in (reference, run))
        lines += [f"{label}: environment {d}" for d in differences(*environments)]
    return lines
