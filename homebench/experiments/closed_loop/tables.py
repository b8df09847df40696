"""The tables of a closed-loop run: per-start outcomes, per-method summary, catchment, pairs.

- ``trials.csv``: one row per trial (the per-start outcomes export).
- ``summary.csv``: per style and method: success rate with a 95 % goal-bootstrap interval
  (:mod:`homebench.analysis.statistics`; the cluster is the goal when there are several
  goals, else the start), median final distance, mean path ratio of the successful trials,
  mean steps, the share of steps without an estimate, seconds per step, and the catchment area.
- ``catchment.csv``: per style, method and goal: the catchment area in m^2, the floor's
  share of starts each stands for (cells x cell area), and the free floor the starts cover.
- ``paired.csv``: McNemar's exact test (:func:`~homebench.analysis.statistics.mcnemar_exact`)
  of every pair of methods on success from the same starts, per style, Holm-adjusted.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from homebench.analysis.statistics import GoalResampler, holm, mcnemar_exact, mean_interval
from homebench.experiments.closed_loop.config import ClosedLoopConfig
from homebench.fileio import write_text_atomic

TABLES_DIR = "tables"
TRIAL_KEYS = ("style", "method", "goal", "start")


def catchment_area(success: ArrayLike, area: ArrayLike) -> float:
    """Floor (m^2) from which homing succeeds: the areas (n,) of the successful starts (n,)."""
    return float(np.sum(np.asarray(area, dtype=np.float64)[np.asarray(success, dtype=bool)]))


def catchment_map(frame: pd.DataFrame) -> NDArray[np.float64]:
    """Success per lattice cell of one (style, method, goal)'s trials: shape (rows, columns)
    over the cells from (0, 0) to the largest, 1.0 success, 0.0 failure, NaN no start."""
    cells = frame[["cell_i", "cell_j"]].to_numpy(dtype=np.int64)
    shape = (int(cells[:, 1].max()) + 1, int(cells[:, 0].max()) + 1) if len(cells) else (0, 0)
    out = np.full(shape, np.nan)
    out[cells[:, 1], cells[:, 0]] = frame["success"].to_numpy(dtype=np.float64)
    return out


def trials_frame(records: list[dict[str, Any]], config: ClosedLoopConfig) -> pd.DataFrame:
    """The trials' summaries, ordered by style and method (config order), goal and start."""
    frame = pd.DataFrame([r["summary"] for r in records])
    if frame.empty:
        return frame
    ranks = {label: k for k, label in enumerate(config.labels())}
    styles = {s: k for k, s in enumerate(dict.fromkeys(frame["style"]))}
    order = np.lexsort((frame["start"], frame["goal"], frame["method"].map(ranks),
                        frame["style"].map(styles)))  # fmt: skip
    return frame.iloc[order].reset_index(drop=True)


def _clusters(group: pd.DataFrame) -> NDArray[np.int64]:
    """The bootstrap's unit per trial: the goal when a method has several, else the start."""
    column = "goal" if group["goal"].nunique() > 1 else "start"
    return group[column].to_numpy(dtype=np.int64)


def summary_table(frame: pd.DataFrame, seed: int) -> pd.DataFrame:
    """One row per style and method (see the module docstring)."""
    rows = []
    for (style, method), group in frame.groupby(["style", "method"], sort=False):
        success = group["success"].to_numpy(dtype=bool)
        rate = mean_interval(success.astype(float), GoalResampler(_clusters(group), seed=seed))
        steps = group["steps"].to_numpy(dtype=np.float64)
        per_step = group["see_s_per_step"] + group["home_s_per_step"]
        areas = [catchment_area(g["success"], g["cell_area_m2"]) for _, g in group.groupby("goal")]
        rows.append({
            "style": style, "method": method, "trials": len(group),
            "goals": group["goal"].nunique(),
            "success": rate.estimate, "success_lo": rate.lo, "success_hi": rate.hi,
            "final_distance_m": float(group["final_distance_m"].median()),
            "path_ratio": float(group.loc[success, "path_ratio"].mean()) if success.any()
            else float("nan"),
            "steps": float(steps.mean()),
            "no_estimate_share": float(group["no_estimates"].sum() / max(steps.sum(), 1.0)),
            "collisions": int((group["outcome"] == "collision").sum()),
            "outside": int((group["outcome"] == "outside").sum()),
            "s_per_step": float(per_step.mean()),
            "catchment_m2": float(np.mean(areas)),
        })  # fmt: skip
    return pd.DataFrame(rows)


def catchment_table(frame: pd.DataFrame) -> pd.DataFrame:
    """One row per style, method and goal: catchment area, starts, free floor they cover."""
    rows = []
    for (style, method, goal), g in frame.groupby(["style", "method", "goal"], sort=False):
        rows.append({
            "style": style, "method": method, "goal": goal, "starts": len(g),
            "successes": int(g["success"].sum()),
            "catchment_m2": catchment_area(g["success"], g["cell_area_m2"]),
            "covered_m2": float(g["cell_area_m2"].sum()),
        })  # fmt: skip
    return pd.DataFrame(rows)


def paired_table(frame: pd.DataFrame) -> pd.DataFrame:
    """McNemar's exact test of every pair of methods per style on the same (goal, start)s,
    with Holm-adjusted p-values within each style."""
    rows = []
    for style, group in frame.groupby("style", sort=False):
        wide = group.pivot_table(index=["goal", "start"], columns="method", values="success",
                                 aggfunc="first")  # fmt: skip
        methods = list(dict.fromkeys(group["method"]))
        tests = []
        for a, b in itertools.combinations(methods, 2):
            both = wide[[a, b]].dropna()
            test = mcnemar_exact(both[a].astype(bool), both[b].astype(bool))
            tests.append({"style": style, "method_a": a, "method_b": b,
                          "starts": test.n_starts, "only_a": test.only_a,
                          "only_b": test.only_b, "p": test.p_value})  # fmt: skip
        adjusted = holm([t["p"] for t in tests]) if tests else []
        rows += [{**t, "p_holm": float(p)} for t, p in zip(tests, adjusted, strict=True)]
    return pd.DataFrame(rows, columns=["style", "method_a", "method_b", "starts", "only_a",
                                       "only_b", "p", "p_holm"])  # fmt: skip


def write_tables(
    records: list[dict[str, Any]], config: ClosedLoopConfig, folder: Path
) -> pd.DataFrame:
    """Write trials, summary, catchment and paired tables as CSV; the summary."""
    folder.mkdir(parents=True, exist_ok=True)
    frame = trials_frame(records, config)
    if frame.empty:
        return frame
    summary = summary_table(frame, config.seed)
    tables = {"trials": frame, "summary": summary, "catchment": catchment_table(frame),
              "paired": paired_table(frame)}  # fmt: skip
    for name, table in tables.items():
        write_text_atomic(folder / f"{name}.csv", table.to_csv(index=False))
    return summary
