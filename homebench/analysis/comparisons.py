"""Paired comparisons of a run's methods, condition by condition: AE and return ratio.

Input: the run's ``pairs`` and ``rr_starts`` tables (:mod:`homebench.evaluation.results`).
Two methods' pairs are matched on their goal (seed, goal_i, goal_j) and current position,
their return-ratio starts on the goal and the start; only matched pairs are compared (a pair
that failed in either method is not). The tests are those of
:mod:`homebench.analysis.statistics`: a goal-level paired bootstrap interval and sign-flip
p-value (use these for findings) beside a per-pair Wilcoxon or McNemar p-value that ignores
the clustering of pairs by goal. Differences are always B - A.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd

from homebench.analysis.metrics import Missing
from homebench.analysis.statistics import (
    LEVEL,
    N_BOOT,
    AeComparison,
    Interval,
    RrComparison,
    compare_ae,
    compare_rr,
    holm,
    row_codes,
)
from homebench.analysis.tables import gives_directions, goal_labels
from homebench.config import AhcDefinition
from homebench.hashing import derived_seed

#: Columns of :func:`comparison_table`.
COLUMNS = [
    "condition",
    "metric",
    "method_a",
    "method_b",
    "value_a",
    "value_b",
    "difference",
    "lo",
    "hi",
    "n_pairs",
    "n_goals",
    "n_excluded",
    "p_goal",
    "p_goal_holm",
    "p_pair",
    "p_pair_holm",
    "pair_test",
]


@dataclass(frozen=True)
class MethodComparison:
    """Method ``b`` against method ``a`` under ``condition``: AE on the matched pairs, RR on
    the matched starts (all NaN when no goal has complete fields for both)."""

    condition: str
    a: str
    b: str
    ae: AeComparison
    rr: RrComparison


#: One cell's rows: keys (n, 5) int (the goal's labels, then a position) and values (n,).
Cell = tuple[np.ndarray, np.ndarray]
#: Per (condition, method): the cell of its rows.
Keyed = dict[tuple[str, str], Cell]
EMPTY_CELL: Cell = (np.empty((0, 5), np.int64), np.empty(0))
PAIR_POSITION = ["current_i", "current_j"]
START_POSITION = ["start_i", "start_j"]


def keyed_cells(table: pd.DataFrame, position: list[str], value: str) -> Keyed:
    """The rows of ``table`` per (condition, method) as keys and ``value`` (float); pairs whose
    method raised (an ``error``) are in no comparison, as in no metric, nor are those of a
    method that gives no home direction (a compass)."""
    if table.empty:
        return {}
    if "error" in table.columns:
        table = table[table["error"].isna()]
    table = table[gives_directions(table)]
    columns = ["seed", "goal_i", "goal_j", *position, value]
    return {
        key: (
            np.column_stack([goal_labels(rows), rows[position].to_numpy(dtype=np.int64)]),
            rows[value].to_numpy(dtype=float),
        )
        for key, rows in table.groupby(["condition", "method"], sort=False)[columns]
    }


def matched(a: Cell, b: Cell) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The values of cells ``a`` and ``b`` on their common keys, shapes (n,) and (n,), and
    the goal labels of each, (n, 3)."""
    (keys_a, values_a), (keys_b, values_b) = a, b
    code = row_codes(np.vstack([keys_a, keys_b]))[0]
    _, ia, ib = np.intersect1d(code[: len(keys_a)], code[len(keys_a) :], return_indices=True)
    return values_a[ia], values_b[ib], keys_a[ia, :3]


def compare_cells(
    ae: tuple[Cell, Cell],
    rr: tuple[Cell, Cell],
    seed: int,
    missing: Missing = "orthogonal",
    n_boot: int = N_BOOT,
    level: float = LEVEL,
    definition: AhcDefinition = "cos_mean_ae",
) -> tuple[AeComparison, RrComparison]:
    """B against A on their matched pairs (``ae``: the AE cells of A and B) and matched
    return-ratio starts (``rr``: their success cells), resampled and flipped from ``seed``."""
    ae_a, ae_b, goal = matched(*ae)
    ok_a, ok_b, start_goal = matched(*rr)
    return (
        compare_ae(ae_a, ae_b, goal, missing, n_boot, level, seed, definition),
        compare_rr(ok_a.astype(bool), ok_b.astype(bool), start_goal, n_boot, level, seed),
    )


def compare_methods(
    pairs: pd.DataFrame,
    rr_starts: pd.DataFrame,
    condition: str,
    a: str,
    b: str,
    missing: Missing = "orthogonal",
    n_boot: int = N_BOOT,
    level: float = LEVEL,
    definition: AhcDefinition = "cos_mean_ae",
) -> MethodComparison:
    """Compare method ``b`` with method ``a`` (labels) under ``condition``.

    ``missing``: how a pair without an estimate in either method is compared (see
    :func:`~homebench.analysis.statistics.compare_ae`); ``definition``: the AHC's. The seed
    of the resamples and sign flips is derived from (condition, a, b): the same tables give
    the same numbers.
    """
    chosen = [_rows_of(table, condition, (a, b)) for table in (pairs, rr_starts)]
    ae = keyed_cells(chosen[0], PAIR_POSITION, "ae")
    rr = keyed_cells(chosen[1], START_POSITION, "success")
    return _compare(ae, rr, condition, (a, b), missing, n_boot, level, definition)


def _rows_of(table: pd.DataFrame, condition: str, methods: tuple[str, ...]) -> pd.DataFrame:
    if table.empty:
        return table
    return table[(table["condition"] == condition) & table["method"].isin(methods)]


def _compare(
    ae: Keyed,
    rr: Keyed,
    condition: str,
    methods: tuple[str, str],
    missing: Missing,
    n_boot: int,
    level: float,
    definition: AhcDefinition,
) -> MethodComparison:
    a, b = methods
    seed = derived_seed("compare", condition, a, b)
    ae_cells = (ae.get((condition, a), EMPTY_CELL), ae.get((condition, b), EMPTY_CELL))
    rr_cells = (rr.get((condition, a), EMPTY_CELL), rr.get((condition, b), EMPTY_CELL))
    found = compare_cells(ae_cells, rr_cells, seed, missing, n_boot, level, definition)
    return MethodComparison(condition, a, b, *found)


def comparison_table(
    pairs: pd.DataFrame,
    rr_starts: pd.DataFrame,
    missing: Missing = "orthogonal",
    n_boot: int = N_BOOT,
    level: float = LEVEL,
    definition: AhcDefinition = "cos_mean_ae",
) -> pd.DataFrame:
    """Every pair of methods (a before b in label order) within each condition, tidy; the
    AHC by ``definition``.

    One row per (condition, a, b, metric), metric ``mean_ae_deg`` (degrees), ``ahc`` or
    ``rr``: ``value_a``, ``value_b`` (on the compared pairs or starts), ``difference`` = B - A
    with its interval ``lo``, ``hi``; ``n_pairs`` (pairs or starts), ``n_goals``,
    ``n_excluded``; ``p_goal`` (sign flips over goals), ``p_pair`` (``pair_test``: Wilcoxon
    for AE, McNemar for RR) and their Holm-adjusted values ``p_goal_holm``, ``p_pair_holm``.
    Holm's family is the whole table: every AE and every RR comparison (the ``ahc`` row
    shares the AE test of its ``mean_ae_deg`` row and is not counted twice).
    """
    ae = keyed_cells(pairs, PAIR_POSITION, "ae")
    rr = keyed_cells(rr_starts, START_POSITION, "success")
    found = [
        _compare(ae, rr, condition, (a, b), missing, n_boot, level, definition)
        for condition in sorted({c for c, _ in ae})
        for a, b in combinations(sorted(m for c, m in ae if c == condition), 2)
    ]
    rows = [row for k, comparison in enumerate(found) for row in _rows(comparison, 2 * k)]
    table = pd.DataFrame(rows, columns=["test", *COLUMNS])
    for column in ("p_goal", "p_pair"):
        table[f"{column}_holm"] = holm_by_test(table[column], table["test"])
    return table[COLUMNS]


def holm_by_test(p_values: pd.Series, tests: pd.Series) -> pd.Series:
    """Holm-adjusted ``p_values`` of rows that name their test in ``tests`` (aligned): rows
    of one test share its p-value and count once in the family; NaN p-values are no test."""
    first = ~tests.duplicated()
    unique = pd.Series(p_values[first].to_numpy(dtype=float), index=tests[first])
    adjusted = pd.Series(holm(unique), index=unique.index, dtype=float)
    return tests.map(adjusted)


def _rows(found: MethodComparison, first_test: int) -> list[dict[str, object]]:
    """The rows of one comparison: AE in degrees and AHC (test ``first_test``), RR (the next
    test)."""
    ae, rr = found.ae, found.rr
    ae_test = {"test": first_test, "n_excluded": ae.n_excluded, "p_goal": ae.p_goal,
               "p_pair": ae.p_wilcoxon, "pair_test": "wilcoxon"}  # fmt: skip
    rr_test = {"test": first_test + 1, "n_excluded": 0, "p_goal": rr.p_goal,
               "p_pair": rr.mcnemar.p_value, "pair_test": "mcnemar"}  # fmt: skip
    degrees = [i.transformed(np.degrees) for i in (ae.mean_ae_a, ae.mean_ae_b, ae.mean_ae)]
    n_pairs, n_starts = ae.mean_ae.n_pairs, rr.mcnemar.n_starts
    return [
        _row(found, "mean_ae_deg", *degrees, n_pairs) | ae_test,
        _row(found, "ahc", ae.ahc_a, ae.ahc_b, ae.ahc, n_pairs) | ae_test,
        _row(found, "rr", rr.rr_a, rr.rr_b, rr.rr, n_starts) | rr_test,
    ]


def _row(
    found: MethodComparison,
    metric: str,
    value_a: Interval,
    value_b: Interval,
    difference: Interval,
    n_pairs: int,
) -> dict[str, object]:
    return {
        "condition": found.condition,
        "metric": metric,
        "method_a": found.a,
        "method_b": found.b,
        "value_a": value_a.estimate,
        "value_b": value_b.estimate,
        "difference": difference.estimate,
        "lo": difference.lo,
        "hi": difference.hi,
        "n_pairs": n_pairs,
        "n_goals": difference.n_goals,
    }
