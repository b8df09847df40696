"""From job files to tables: the per-pair table and the metric tables of a run folder.

Everything here reads the run folder alone (``plan.json`` lists the run's home jobs, one result
file each), so tables can be rebuilt at any time. A missing or corrupt job file is reported by
name, never skipped silently.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from homebench.config import MetricsConfig
from homebench.errors import DataError
from homebench.evaluation.jobs import read_result
from homebench.evaluation.metrics import HomeField, ae_summary, ahc, ahc_by_distance
from homebench.evaluation.plan import Plan
from homebench.evaluation.return_ratio import catchment, return_ratio
from homebench.fileio import atomic_write, write_text_atomic
from homebench.geometry import Grid

PLAN_FILE = "plan.json"
GROUP = ["condition", "method"]
#: The factors of a pair (every one a column, so tables can group by any), then its position.
LEADING = [
    "seed",
    "condition",
    "current_database",
    "goal_database",
    "method",
    "method_name",
    "goal_i",
    "goal_j",
    "current_i",
    "current_j",
]


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
        index = json.loads(index_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(f"{index_path}: not a homebench run folder (no {PLAN_FILE})") from None
    except ValueError as error:
        raise DataError(f"{index_path}: corrupt ({error})") from None
    frames, missing = [], []
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
        frame["grid"] = json.dumps(record["grid"])
        frames.append(frame)
    if not frames:
        return PairTable(pd.DataFrame(), tuple(missing))
    pairs = pd.concat(frames, ignore_index=True)
    pairs["seed"] = pairs["seed"].astype("Int64")
    pairs["ae_deg"] = np.degrees(pairs["ae"].astype(float))
    order = ["seed", "condition", "method", "goal_i", "goal_j", "current_i", "current_j"]
    pairs = pairs.sort_values(order, kind="stable").reset_index(drop=True)
    leading = LEADING
    return PairTable(
        pairs[leading + [c for c in pairs.columns if c not in leading]], tuple(missing)
    )


def _grid_of(group: pd.DataFrame) -> Grid:
    spec = json.loads(group["grid"].iloc[0])
    return Grid(tuple(spec["shape"]), spec["spacing"], tuple(spec["origin"]))


def goal_fields(
    pairs: pd.DataFrame,
) -> list[tuple[tuple[int | None, str, str, int, int], HomeField, bool]]:
    """One world-frame home field per (condition, method, goal) and whether it covers the grid.

    A field covers the grid when every position but the goal has a pair; return ratios of
    fields that do not are not comparable with the paper's and are reported as NaN.
    """
    fields = []
    for (seed, condition, method, gi, gj), group in pairs.groupby(
        ["seed", "condition", "method", "goal_i", "goal_j"], sort=True, dropna=False
    ):
        grid = _grid_of(group)
        angles = np.full(grid.shape, np.nan)
        estimates = group["estimate_world"].astype(float).to_numpy()
        angles[group["current_i"].to_numpy(), group["current_j"].to_numpy()] = estimates
        complete = len(group) == grid.size - 1
        key = (None if pd.isna(seed) else int(seed), condition, method, int(gi), int(gj))
        fields.append((key, HomeField(grid, (gi, gj), angles), complete))
    return fields


def goal_table(pairs: pd.DataFrame, metrics: MetricsConfig) -> pd.DataFrame:
    """Return ratio (and catchment) per condition, method and goal (the paper's Figure 10)."""
    rr = metrics.return_ratio
    rows = []
    for (seed, condition, method, gi, gj), home_field, complete in goal_fields(pairs):
        row = {"seed": seed, "condition": condition, "method": method, "goal_i": gi, "goal_j": gj}
        if complete:
            max_travel = rr.max_travel
            row["rr"] = return_ratio(home_field, rr.rh, rr.success_radius, max_travel).rr
            if metrics.catchment:
                row["catchment"] = catchment(home_field).ratio
        else:
            row["rr"] = math.nan
            if metrics.catchment:
                row["catchment"] = math.nan
        rows.append(row)
    return pd.DataFrame(rows)


def ahc_table(pairs: pd.DataFrame, metrics: MetricsConfig) -> pd.DataFrame:
    """AHC per distance bin for each condition and method (the paper's Figure 9)."""
    cfg = metrics.ahc
    bins = np.arange(cfg.bin_start_cm, cfg.bin_stop_cm + cfg.bin_step_cm / 2, cfg.bin_step_cm)
    frames = []
    for (condition, method), group in pairs.groupby(GROUP, sort=True):
        table = ahc_by_distance(
            group["ae"].astype(float), group["distance_m"].astype(float), bins, cfg.missing
        )
        table.insert(0, "method", method)
        table.insert(0, "condition", condition)
        frames.append(table)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def summary_table(
    pairs: pd.DataFrame, goals: pd.DataFrame, metrics: MetricsConfig, by: list[str] = GROUP
) -> pd.DataFrame:
    """Headline per ``by`` (method x condition; with "seed" first, per world seed too): AE,
    AHC, RR (mean over goals), share without estimate, times."""
    rows = []
    for key, group in pairs.groupby(by, sort=True, dropna=False):
        factors = dict(zip(by, key, strict=True))
        mask = np.ones(len(goals), dtype=bool)
        for name, value in factors.items():
            column = goals[name]
            mask &= column.isna().to_numpy() if pd.isna(value) else (column == value).to_numpy()
        per_goal = goals[mask]
        ae = group["ae"].astype(float)
        summary = ae_summary(ae)
        describe_ms = pd.concat([group["describe_ms"], group["goal_describe_ms"]])
        row = {
            **factors,
            "pairs": summary["n"],
            "no_estimate_share": summary["missing_share"],
            "mean_ae_deg": summary["mean_deg"],
            "median_ae_deg": summary["median_deg"],
            "ahc": ahc(ae, metrics.ahc.missing),
            "rr": per_goal["rr"].mean(),
            "describe_ms": describe_ms.mean(),
            "home_ms": group["home_ms"].mean(),
        }
        if metrics.catchment:
            row["catchment"] = per_goal["catchment"].mean()
        rows.append(row)
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class RunTables:
    """The tables of a run; ``summary_by_seed`` is empty unless the run swept world seeds."""

    pairs: pd.DataFrame
    summary: pd.DataFrame
    goals: pd.DataFrame
    ahc: pd.DataFrame
    missing_jobs: tuple[str, ...]
    summary_by_seed: pd.DataFrame = field(default_factory=pd.DataFrame)


def build_tables(run_dir: Path, metrics: MetricsConfig) -> RunTables:
    loaded = load_pairs(run_dir)
    if loaded.pairs.empty:
        empty = pd.DataFrame()
        return RunTables(empty, empty, empty, empty, loaded.missing_jobs)
    pairs = loaded.pairs
    goals = goal_table(pairs, metrics)
    swept = pairs["seed"].nunique(dropna=False) > 1
    return RunTables(
        pairs,
        summary_table(pairs, goals, metrics),
        goals,
        ahc_table(pairs, metrics),
        loaded.missing_jobs,
        summary_table(pairs, goals, metrics, ["seed", *GROUP]) if swept else pd.DataFrame(),
    )


def write_tables(tables: RunTables, run_dir: Path, table_format: str) -> list[Path]:
    """Write the tables under ``run_dir/tables`` (pairs as CSV or Parquet, the rest CSV)."""
    folder = Path(run_dir) / "tables"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    pairs = tables.pairs.drop(columns=["grid"], errors="ignore")
    if table_format == "parquet":
        path = folder / "pairs.parquet"
        with atomic_write(path) as f:
            pairs.to_parquet(f, index=False)
    else:
        path = folder / "pairs.csv"
        write_text_atomic(path, pairs.to_csv(index=False, float_format="%.6g"))
    written.append(path)
    named = [("summary", tables.summary), ("goals", tables.goals), ("ahc", tables.ahc)]
    if not tables.summary_by_seed.empty:
        named.append(("summary_by_seed", tables.summary_by_seed))
    for name, table in named:
        path = folder / f"{name}.csv"
        write_text_atomic(path, table.to_csv(index=False, float_format="%.6g"))
        written.append(path)
    return written
