"""From job files to tables: the per-pair table of a run folder, the tables written from it.

Everything here reads the run folder alone (``plan.json`` lists the run's home jobs, one result
file each), so tables can be rebuilt at any time. A missing or corrupt job file is reported by
name, never skipped silently. What the tables hold and how each metric is computed:
:mod:`homebench.analysis.tables`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from pydantic import ValidationError

from homebench.analysis.tables import (
    LEADING,
    RunTables,
    run_tables,
    with_rotation_errors,
)
from homebench.bounds import MAX_JOBS
from homebench.config import MetricsConfig
from homebench.errors import DataError
from homebench.evaluation.jobs import read_result
from homebench.evaluation.plan import Plan
from homebench.evaluation.records import PLAN, first_problem
from homebench.fileio import atomic_write, read_record_text, write_text_atomic

PLAN_FILE = "plan.json"


#: Largest plan read: a few hundred bytes per job of the largest run (homebench.bounds).
MAX_PLAN_BYTES = 512 * MAX_JOBS


def write_plan_index(plan: Plan, run_dir: Path) -> None:
    """Record which home jobs make up the run (their keys and what they are)."""
    index = [
        {
            "key": job.key,
            "condition": job.condition,
            "method": job.method.label,
            "goal": [job.goal.i, job.goal.j],
        }
        for job in plan.home
    ]
    write_text_atomic(run_dir / PLAN_FILE, json.dumps(index, indent=1) + "\n")


@dataclass(frozen=True)
class PairTable:
    pairs: pd.DataFrame
    missing_jobs: tuple[str, ...]  # "key (condition, method, goal)" of jobs without a result


def load_pairs(run_dir: Path) -> PairTable:
    """The per-pair table of a run, sorted by condition, method, goal and current position."""
    index_path = Path(run_dir) / PLAN_FILE
    try:
        index = PLAN.validate_json(read_record_text(index_path, MAX_PLAN_BYTES))
    except FileNotFoundError:
        raise DataError(f"{index_path}: not a homebench run folder (no {PLAN_FILE})") from None
    except ValidationError as error:
        raise DataError(f"{index_path}: corrupt ({first_problem(error)})") from None
    except (OSError, ValueError) as error:
        raise DataError(f"{index_path}: corrupt ({error})") from None
    frames, missing = [], []
    grids: dict[str, str] = {}
    for entry in index:
        record = read_result(Path(run_dir) / "jobs" / f"{entry['key']}.json", entry["key"])
        if record is None:
            missing.append(
                f"jobs/{entry['key']}.json ({entry['condition']}, {entry['method']}, "
                f"goal {tuple(entry['goal'])})"
            )
            continue
        frame = pd.DataFrame.from_records(record["rows"])
        for column in reversed(LEADING[:-2]):
            frame.insert(0, column, record[column])
        for name, value in sorted(record["params"].items()):
            frame[f"param.{name}"] = json.dumps(value) if isinstance(value, list | dict) else value
        grid = json.dumps(record["grid"])  # one object per grid: posed places list every pose
        frame["grid"] = grids.setdefault(grid, grid)
        frame["goal_heading"] = float(record["goal_heading"])
        frame["gives_direction"] = bool(record["gives_direction"])
        frames.append(frame)
    if not frames:
        return PairTable(pd.DataFrame(), tuple(missing))
    pairs = pd.concat(frames, ignore_index=True)
    pairs["seed"] = pairs["seed"].astype("Int64")
    pairs["style"] = pairs["style"].astype("string")
    pairs["ae_deg"] = np.degrees(pairs["ae"].astype(float))
    pairs = with_rotation_errors(pairs)
    order = ["style", "seed", "condition", "method", "goal_i", "goal_j", "current_i", "current_j"]
    pairs = pairs.sort_values(order, kind="stable").reset_index(drop=True)
    leading = LEADING
    return PairTable(
        pairs[leading + [c for c in pairs.columns if c not in leading]], tuple(missing)
    )


def build_tables(run_dir: Path, metrics: MetricsConfig) -> RunTables:
    """The tables of the run in ``run_dir`` (:func:`~homebench.analysis.tables.run_tables` of
    its job files' pairs)."""
    loaded = load_pairs(run_dir)
    return run_tables(loaded.pairs, loaded.missing_jobs, metrics)


#: Columns of the pair table that are angles in radians (:data:`~homebench.evaluation.jobs.
#: ROW_COLUMNS`); the written table names each ``<name>_rad`` and adds ``<name>_deg``.
ANGLE_COLUMNS = (
    "rotation",
    "heading",
    "goal_heading",
    "estimate",
    "estimate_world",
    "truth",
    "ae",
    "rotation_estimate",
    "rotation_truth",
    "rotation_error",
)


def pairs_with_units(pairs: pd.DataFrame) -> pd.DataFrame:
    """``pairs`` as written: without ``grid``, every angle as ``<name>_rad`` followed by
    ``<name>_deg`` (ANGLE_COLUMNS; ``ae_deg`` is ``ae``'s)."""
    written = pairs.drop(columns=["grid", "ae_deg"], errors="ignore")
    for name in ANGLE_COLUMNS:
        if name in written.columns:
            place = written.columns.get_loc(name)
            radians = written.pop(name).astype(float)
            written.insert(place, f"{name}_rad", radians)
            written.insert(place + 1, f"{name}_deg", np.degrees(radians))
    return written


def write_tables(tables: RunTables, run_dir: Path, table_format: str) -> list[Path]:
    """Write the tables under ``run_dir/tables``: pairs as CSV or Parquet
    (:func:`pairs_with_units`), the rest CSV: summary, goals, ahc, rr_starts,
    ``comparisons`` (:func:`method_comparisons`) and summary_by_seed when seeds are swept."""
    folder = Path(run_dir) / "tables"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    pairs = pairs_with_units(tables.pairs)
    if table_format == "parquet":
        path = folder / "pairs.parquet"
        with atomic_write(path) as f:
            pairs.to_parquet(f, index=False)
    else:
        path = folder / "pairs.csv"
        write_text_atomic(path, pairs.to_csv(index=False, float_format="%.6g"))
    written.append(path)
    named = [
        ("summary", tables.summary),
        ("goals", tables.goals),
        ("ahc", tables.ahc),
        ("rr_starts", tables.rr_starts),
        ("comparisons", tables.comparisons),
        ("bands", tables.bands),
    ]
    if not tables.summary_by_seed.empty:
        named.append(("summary_by_seed", tables.summary_by_seed))
    for name, table in named:
        path = folder / f"{name}.csv"
        write_text_atomic(path, table.to_csv(index=False, float_format="%.6g"))
        written.append(path)
    return written
