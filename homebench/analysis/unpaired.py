"""Unpaired comparison of two sets of pairs (two runs on different goals): goal level.

The paired tests of :mod:`homebench.analysis.statistics` need the same pairs in both sets.
When the goals differ, each set's goals are resampled on their own (two independent goal
bootstraps, :class:`~homebench.analysis.statistics.GoalResampler`) and the interval of the
difference B - A is taken over the differences of the resampled metrics; it is expanded for the
smaller set's number of goals. The p-value is a goal permutation test: under the null both
sets' goals come from one population, so the goals are dealt to A and B anew (all ways up to
``N_PERMUTATIONS``, otherwise that many at random, seeded) and the statistic is
``|mean_B - mean_A|`` with means pooled over pairs, as in the metric.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import combinations
from math import comb

import numpy as np
from numpy.typing import ArrayLike

from homebench.analysis.statistics import LEVEL, N_BOOT, GoalResampler, Interval, Replicates
from homebench.geometry import FloatArray
from homebench.hashing import derived_seed

N_PERMUTATIONS = 20_000
_TIE = 1e-10  # a permuted statistic this close to the observed one ties


@dataclass(frozen=True)
class UnpairedMeans:
    """The pooled mean of set A and of set B (``a``, ``b``: estimate and resamples, drawn
    independently) and the goal permutation p-value of their difference."""

    a: Replicates
    b: Replicates
    p_value: float

    def difference(
        self, f: Callable[[FloatArray], FloatArray] = np.asarray, level: float = LEVEL
    ) -> Interval:
        """``f(mean_B) - f(mean_A)`` with its interval (``f``: e.g. cos for AHC); its
        ``n_goals`` is the smaller set's, which sets the expansion of the level."""
        a, b = self.a, self.b
        estimate = float(f(np.array(b.estimate)) - f(np.array(a.estimate)))
        n_goals = min(a.n_goals, b.n_goals)
        values = f(b.values) - f(a.values)
        return Replicates(estimate, values, a.n_pairs + b.n_pairs, n_goals).interval(level)


def unpaired_means(
    values_a: ArrayLike,
    goal_a: ArrayLike,
    values_b: ArrayLike,
    goal_b: ArrayLike,
    n_boot: int = N_BOOT,
    seed: int = 0,
) -> UnpairedMeans:
    """Compare the pooled means of ``values_a`` and ``values_b`` (each (n,) with its goal
    labels, as in :class:`GoalResampler`; NaN values left out). The two bootstraps and the
    permutations draw from seeds derived from ``seed``."""
    sets = [
        (np.asarray(v, dtype=np.float64), g) for v, g in ((values_a, goal_a), (values_b, goal_b))
    ]
    resamplers = [
        GoalResampler(goal, n_boot, derived_seed("unpaired", seed, k))
        for k, (_, goal) in enumerate(sets)
    ]
    means = [r.mean(v) for r, (v, _) in zip(resamplers, sets, strict=True)]
    sums = [_goal_totals(r, v) for r, (v, _) in zip(resamplers, sets, strict=True)]
    p = permutation_test(*sums[0], *sums[1], seed=derived_seed("unpaired", seed, "test"))
    return UnpairedMeans(means[0], means[1], p)


def _goal_totals(resampler: GoalResampler, values: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per goal with a finite value: the sum of its finite values and their number."""
    finite = np.isfinite(values)
    total = resampler.goal_sums(np.where(finite, values, 0.0))
    count = resampler.goal_sums(finite.astype(np.float64))
    return total[count > 0], count[count > 0]


def permutation_test(
    sum_a: ArrayLike,
    count_a: ArrayLike,
    sum_b: ArrayLike,
    count_b: ArrayLike,
    n_permutations: int = N_PERMUTATIONS,
    seed: int = 0,
) -> float:
    """Two-sided p-value that two sets of goals share one pooled mean.

    ``sum_*``, ``count_*``: per goal of each set, the sum of its values and their number
    (shapes (n_a,) and (n_b,)). The statistic ``|sum_B / count_B - sum_A / count_A|`` (pooled
    over the goals dealt to each set) is computed for every way of dealing n_b of the n_a + n_b
    goals to B when there are at most ``n_permutations`` ways (exact p, the smallest possible
    being 1 / comb(n_a + n_b, n_b)), otherwise for ``n_permutations`` random deals:
    ``(1 + hits) / (1 + n_permutations)``. NaN when a set has no goal.
    """
    sums = np.concatenate([np.asarray(sum_a, float), np.asarray(sum_b, float)])
    counts = np.concatenate([np.asarray(count_a, float), np.asarray(count_b, float)])
    n, n_b = sums.size, np.asarray(sum_b).size
    if n_b == 0 or n_b == n:
        return np.nan
    exact = comb(n, n_b) <= n_permutations
    if exact:
        deals = np.zeros((comb(n, n_b), n), dtype=bool)
        for row, chosen in enumerate(combinations(range(n), n_b)):
            deals[row, list(chosen)] = True
    else:
        ranks = np.argsort(np.random.default_rng(seed).random((n_permutations, n)), axis=1)
        deals = ranks < n_b
    observed = np.zeros((1, n), dtype=bool)
    observed[0, n - n_b :] = True
    statistic = _pooled_gap(np.vstack([observed, deals]), sums, counts)
    hits = np.sum(statistic[1:] >= statistic[0] - _TIE)
    return float(hits / len(deals) if exact else (1 + hits) / (1 + len(deals)))


def _pooled_gap(in_b: np.ndarray, sums: FloatArray, counts: FloatArray) -> FloatArray:
    """``|mean_B - mean_A|`` for each deal of goals (``in_b``: (k, n) bool), shape (k,)."""
    weights = in_b.astype(np.float64)
    mean_b = (weights @ sums) / (weights @ counts)
    mean_a = ((1 - weights) @ sums) / ((1 - weights) @ counts)
    return np.abs(mean_b - mean_a)
