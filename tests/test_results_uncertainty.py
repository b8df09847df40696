"""Uncertainty in the run tables (summary, AHC by distance, per-start RR outcomes) and the
comparison table of a run's methods, on synthetic pair tables whose errors are known."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from homebench.analysis.comparisons import COLUMNS, compare_methods, comparison_table
from homebench.analysis.tables import (
    RR_START_COLUMNS,
    RunTables,
    ahc_table,
    goal_tables,
    summary_table,
)
from homebench.config import MetricsConfig
from homebench.evaluation.results import write_tables
from homebench.geometry import Grid, angular_error, world_direction

GRID = Grid((4, 5), 0.3, (-0.45, -0.6))
GOALS = [(i, j) for i in range(4) for j in range(5)][::2]  # 10 goals
METRICS = MetricsConfig()
BOUNDED = ["no_estimate_share", "mean_ae_deg", "ahc", "ahc_missing90", "rr", "catchment"]


def synthetic_pairs(
    errors_deg: dict[str, tuple[float, float]],
    goals: list[tuple[int, int]] = GOALS,
    missing: float = 0.1,
    seed: int = 0,
) -> pd.DataFrame:
    """A run's pair table (columns as ``load_pairs``) under condition "a-b": per method label an
    (offset, goal sd) in degrees. A method's world estimate is the true direction turned by
    10 deg + offset + a goal-level term (that sd) + pair noise (sd 2 deg): its AE is exactly
    that (always positive). A share ``missing`` of the pairs has no estimate."""
    rng = np.random.default_rng(seed)
    grid_json = json.dumps({"shape": list(GRID.shape), "spacing": 0.3, "origin": [-0.45, -0.6]})
    frames = []
    for method, (offset, goal_sd) in errors_deg.items():
        for goal in goals:
            current = [ij for ij in GRID.indices() if ij != goal]
            i, j = np.array(current).T
            xy, goal_xy = GRID.position(i, j), GRID.position(*goal)
            truth = world_direction(xy, goal_xy)
            error = 10.0 + offset + rng.normal(0.0, goal_sd) + rng.normal(0.0, 2.0, len(i))
            estimate = truth + np.radians(error)
            estimate[rng.random(len(i)) < missing] = np.nan
            frames.append(
                pd.DataFrame(
                    {
                        "style": pd.array([pd.NA] * len(i), dtype="string"),
                        "seed": pd.array([pd.NA] * len(i), dtype="Int64"),
                        "condition": "a-b",
                        "current_database": "a",
                        "goal_database": "b",
                        "method": method,
                        "method_name": "fake",
                        "goal_i": goal[0],
                        "goal_j": goal[1],
                        "current_i": i,
                        "current_j": j,
                        "estimate_world": estimate,
                        "ae": angular_error(estimate, truth),
                        "distance_m": np.hypot(*(xy - goal_xy).T),
                        "describe_ms": 1.0,
                        "goal_describe_ms": 1.0,
                        "home_ms": 2.0,
                        "grid": grid_json,
                    }
                )
            )
    return pd.concat(frames, ignore_index=True)


def tables(pairs: pd.DataFrame) -> dict[str, pd.DataFrame]:
    goals, rr_starts = goal_tables(pairs, METRICS)
    return {
        "summary": summary_table(pairs, goals, METRICS),
        "ahc": ahc_table(pairs, METRICS),
        "goals": goals,
        "rr_starts": rr_starts,
    }


@pytest.fixture(scope="module")
def two_methods() -> pd.DataFrame:
    return synthetic_pairs({"a": (0.0, 3.0), "b": (5.0, 3.0)})


def test_summary_metrics_have_bounds_and_goal_counts(two_methods: pd.DataFrame) -> None:
    summary = tables(two_methods)["summary"].set_index("method")
    for column in ["pairs", "no_estimate_share", "mean_ae_deg", "median_ae_deg", "ahc", "rr",
                   "describe_ms", "home_ms", "catchment"]:  # fmt: skip
        assert column in summary.columns  # the report's columns stay
    assert (summary["n_goals"] == len(GOALS)).all()
    assert (summary["pairs"] == len(GOALS) * (GRID.size - 1)).all()
    for metric in BOUNDED:
        lo, value, hi = (summary[f"{metric}{end}"] for end in ("_lo", "", "_hi"))
        assert (lo <= value + 1e-12).all() and (value <= hi + 1e-12).all(), metric
        assert (hi > lo).all() or metric == "catchment", metric
    # about 10 deg + goal-level sd 3 deg over 10 goals: the interval is a few degrees wide
    width = summary["mean_ae_deg_hi"] - summary["mean_ae_deg_lo"]
    assert ((width > 1.0) & (width < 10.0)).all()
    assert (summary["ahc_missing90"] < summary["ahc"]).all()  # 10 % missing cost 90 deg each


def test_tables_do_not_depend_on_row_order(two_methods: pd.DataFrame) -> None:
    """The bounds are bit for bit the same (goals numbered in sorted order, each goal summed in
    sorted order); the estimates of the AHC bins are plain means (``load_pairs`` sorts the
    pairs anyway), equal up to rounding."""
    shuffled = two_methods.sample(frac=1.0, random_state=3).reset_index(drop=True)
    first, again = tables(two_methods), tables(shuffled)
    for name, table in first.items():
        pd.testing.assert_frame_equal(table, again[name], rtol=1e-13, obj=name)
        exact = [c for c in table.columns if c.endswith(("_lo", "_hi")) or c == "n_goals"]
        pd.testing.assert_frame_equal(table[exact], again[name][exact], check_exact=True)


def test_single_goal_has_no_interval_and_writes_empty_fields(tmp_path: Path) -> None:
    pairs = synthetic_pairs({"a": (0.0, 3.0)}, goals=[(1, 2)])
    made = tables(pairs)
    row = made["summary"].iloc[0]
    assert row["n_goals"] == 1 and math.isfinite(row["ahc"])
    for metric in BOUNDED:
        assert math.isnan(row[f"{metric}_lo"]) and math.isnan(row[f"{metric}_hi"]), metric
    run = RunTables(pairs, made["summary"], made["goals"], made["ahc"], (),
                    rr_starts=made["rr_starts"])  # fmt: skip
    write_tables(run, tmp_path, "csv")
    cells = pd.read_csv(tmp_path / "tables" / "summary.csv", dtype=str, keep_default_na=False)
    for metric in BOUNDED:  # an empty field, not "nan"
        assert cells.loc[0, f"{metric}_lo"] == cells.loc[0, f"{metric}_hi"] == "", metric


def test_rr_starts_are_every_start_of_every_goal(two_methods: pd.DataFrame, tmp_path: Path) -> None:
    made = tables(two_methods)
    starts, goals = made["rr_starts"], made["goals"]
    assert list(starts.columns) == RR_START_COLUMNS
    assert len(starts) == 2 * len(GOALS) * GRID.size
    keys = ["method", "goal_i", "goal_j"]
    rr = starts.groupby(keys)["success"].mean()
    pd.testing.assert_series_equal(rr, goals.set_index(keys)["rr"], check_names=False)
    np.testing.assert_allclose(starts["path_length"], 0.8 * starts["steps"])
    assert not starts.loc[starts["no_estimate"], "success"].any()
    at_goal = (starts["start_i"] == starts["goal_i"]) & (starts["start_j"] == starts["goal_j"])
    assert starts.loc[at_goal, "success"].all() and (starts.loc[at_goal, "steps"] == 0).all()
    run = RunTables(two_methods, made["summary"], goals, made["ahc"], (), rr_starts=starts)
    written = write_tables(run, tmp_path, "csv")
    assert tmp_path / "tables" / "rr_starts.csv" in written
    back = pd.read_csv(tmp_path / "tables" / "rr_starts.csv")
    assert list(back.columns) == RR_START_COLUMNS and len(back) == len(starts)


def test_goal_table_gives_the_share_of_rr_walks_ended_by_an_abstention(
    two_methods: pd.DataFrame,
) -> None:
    goals, starts = goal_tables(two_methods, METRICS)
    keys = ["method", "goal_i", "goal_j"]
    share = starts.groupby(keys)["no_estimate"].mean()
    assert share.gt(0).any()  # 10 % of the pairs have no estimate
    pd.testing.assert_series_equal(
        share, goals.set_index(keys)["rr_no_estimate_share"], check_names=False
    )


def test_rr_reads_an_abstention_as_the_run_config_says(two_methods: pd.DataFrame) -> None:
    """metrics.return_ratio.no_estimate reaches the goal table and the starts: ``arrived``
    turns walks that end next to the goal into successes, and no other."""
    arrived = MetricsConfig(return_ratio={"no_estimate": "arrived"})
    strict, strict_starts = goal_tables(two_methods, METRICS)
    lenient, lenient_starts = goal_tables(two_methods, arrived)
    changed = strict_starts["success"] != lenient_starts["success"]
    assert changed.any() and lenient_starts.loc[changed, "success"].all()
    assert lenient_starts.loc[changed, "no_estimate"].all()
    assert (lenient["rr"] >= strict["rr"]).all() and (lenient["rr"] > strict["rr"]).any()
    pd.testing.assert_series_equal(strict["rr_no_estimate_share"], lenient["rr_no_estimate_share"])


def test_ahc_bins_gain_bounds_and_the_share_without_estimate(two_methods: pd.DataFrame) -> None:
    made = tables(two_methods)
    ahc, summary = made["ahc"], made["summary"].set_index("method")
    filled = ahc[ahc["n"] > 0]
    np.testing.assert_allclose(filled["no_estimate_share"], filled["n_missing"] / filled["n"])
    assert (filled["n_goals"] <= len(GOALS)).all()
    defined = filled[filled["ahc_lo"].notna()]
    assert (defined["ahc_lo"] <= defined["ahc"]).all()
    assert (defined["ahc"] <= defined["ahc_hi"]).all()
    # the "all" row draws the same resamples as the summary (same cell, same seed); equal up
    # to rounding (one matrix product over all bins against one over all pairs)
    overall = ahc[ahc["bin"] == "all"].set_index("method")
    for column in ["ahc", "ahc_lo", "ahc_hi", "ahc_missing90_lo", "no_estimate_share_hi"]:
        np.testing.assert_allclose(overall[column], summary[column], rtol=1e-13, err_msg=column)
    assert (overall["n_goals"] == summary["n_goals"]).all()


# --------------------------------------------------------------------------- comparisons


@pytest.fixture(scope="module")
def three_methods() -> tuple[pd.DataFrame, pd.DataFrame]:
    """``a``; ``a-again``, the same method drawn again (another seed: new goal-level terms
    and pair noise, same mean); ``b``, whose AE is 6 deg larger; every pair has an estimate.
    10 goals: the sign-flip test can reach 2 / 2**10, still below 0.05 after Holm over the
    table's 6 tests (3 AE, 3 RR)."""
    errors = {"a": (0.0, 1.5), "a-again": (0.0, 1.5), "b": (6.0, 1.5)}
    pairs = synthetic_pairs(errors, missing=0.0, seed=4)
    return pairs, goal_tables(pairs, METRICS)[1]


def test_comparison_table_reports_the_known_difference_only(three_methods) -> None:
    pairs, rr_starts = three_methods
    table = comparison_table(pairs, rr_starts)
    assert list(table.columns) == COLUMNS
    assert len(table) == 3 * 3  # (a, a-again), (a, b), (a-again, b) x (AE, AHC, RR)
    ae = table[table["metric"] == "mean_ae_deg"].set_index(["method_a", "method_b"])
    known = ae.loc[("a", "b")]
    assert known["lo"] <= 6.0 <= known["hi"] and known["lo"] > 0
    assert known["p_goal"] == pytest.approx(2 / 2**10) and known["p_goal_holm"] < 0.05
    assert (known["n_pairs"], known["n_goals"]) == (len(GOALS) * (GRID.size - 1), len(GOALS))
    same = ae.loc[("a", "a-again")]
    assert same["p_goal_holm"] > 0.05 and same["lo"] <= 0.0 <= same["hi"]
    ahc = table[table["metric"] == "ahc"].set_index(["method_a", "method_b"])
    assert ahc.loc[("a", "b"), "difference"] < 0  # b errs more: lower AHC
    assert (ahc["p_goal_holm"] == ae["p_goal_holm"]).all()  # one test, counted once
    # Holm over 6 tests: the smallest p is multiplied by the number of tests that have a p
    tests = table[table["metric"] != "ahc"]
    m = tests["p_goal"].notna().sum()
    assert tests["p_goal_holm"].min() == pytest.approx(min(1.0, m * tests["p_goal"].min()))
    rr = table[table["metric"] == "rr"]
    assert (rr["pair_test"] == "mcnemar").all() and (rr["n_pairs"] == len(GOALS) * GRID.size).all()


def test_compare_methods_is_seeded_by_the_cell_and_missing_rule_counts(
    two_methods: pd.DataFrame,
) -> None:
    pairs = two_methods
    rr_starts = goal_tables(pairs, METRICS)[1]
    first = compare_methods(pairs, rr_starts, "a-b", "a", "b")
    assert first == compare_methods(pairs.iloc[::-1], rr_starts.iloc[::-1], "a-b", "a", "b")
    excluded = compare_methods(pairs, rr_starts, "a-b", "a", "b", missing="exclude")
    pair = ["goal_i", "goal_j", "current_i", "current_j"]
    either = pairs.assign(none=pairs["ae"].isna()).groupby(pair)["none"].any()  # a or b
    assert excluded.ae.n_excluded == int(either.sum()) > 0
    assert first.ae.n_excluded == 0
    absent = compare_methods(pairs, rr_starts, "a-b", "a", "nobody")
    assert absent.ae.mean_ae.n_pairs == 0 and math.isnan(absent.ae.p_goal)
    assert math.isnan(absent.rr.mcnemar.p_value)


def test_comparison_table_of_nothing_is_empty() -> None:
    empty = comparison_table(pd.DataFrame(), pd.DataFrame())
    assert empty.empty and list(empty.columns) == COLUMNS


def test_failed_pairs_are_in_no_comparison(two_methods: pd.DataFrame) -> None:
    failed = two_methods.assign(error=None)
    failed.loc[(failed["method"] == "b") & (failed["goal_i"] == 0), "error"] = "ValueError: x"
    found = compare_methods(failed, pd.DataFrame(), "a-b", "a", "b")
    expected = int((two_methods["goal_i"] != 0).sum() / 2)
    assert found.ae.mean_ae.n_pairs == expected
