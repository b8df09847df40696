"""Uncertainty of the metrics: goal-clustered bootstrap intervals and paired tests.

**The goal is the unit of replication.** All pairs of one goal share its image and its home
vector field, and all return-ratio starts of a goal follow that one field, so they are not
independent observations. Intervals therefore resample *goals* with replacement and recompute a
metric over the chosen goals' pairs (the cluster bootstrap, Davison & Hinkley 1997, sec. 3.8),
and the goal-level test flips the signs of whole goals. The per-pair tests (Wilcoxon signed
rank, McNemar) are given beside them but treat pairs as independent: on clustered pairs their
p-values are too small (anti-conservative). A finding should rest on the goal-level numbers,
and needs goals: the exact sign-flip test of n goals cannot go below p = 2 / 2**n, so 5 goals
never reach 0.05, and Holm over m tests needs 2 / 2**n < 0.05 / m.

**Intervals** are *expanded percentile* intervals (Hesterberg 2015, "What teachers should know
about the bootstrap", The American Statistician 69(4)): percentiles of the resampled metric at
a level widened for the number of goals n, ``2 Phi(sqrt(n / (n - 1)) t_{n-1}) - 1`` instead of
``2 Phi(z) - 1``. Why percentiles: they respect monotone transformations (the AHC interval is
exactly cos of the mean-AE interval, and rates stay in [0, 1]) and need no variance formula
for the ratio estimators used here. Why expanded: a benchmark has few goals (seed 001: 5), and
the plain percentile interval of a mean of n clusters is too narrow by about
``sqrt((n - 1) / n)`` and misses the t-distribution's tails: in the simulation of
``tests/test_statistics.py`` it covers 84 % for 5 goals at a nominal 95 %, the expanded one
92 % (10 goals: 90 % and 94 %); the expansion fades for many goals. BCa was not chosen: its
acceleration comes from a jackknife over the goals, which for 5 goals is 5 numbers. No
bootstrap helps with very few goals: an interval cannot reach beyond the range of the per-goal
values, so 3 goals cover about 75 % whatever the level; ``n_goals`` stands beside every
interval for that reason.

**Speed.** A resample is a vector of counts, how often each goal was drawn: ``counts`` has
shape (n_boot, n_goals), multinomial. Every metric here is a ratio of sums over pairs (a mean
over the pairs with a value), so over all resamples at once it is
``(counts @ goal_sums(num)) / (counts @ goal_sums(den))``: no loop over resamples.

**Reproducibility.** Goals are numbered in sorted label order and each goal's values are summed
in sorted value order, so the same values and seed give identical results whatever the order
of the rows.

**Cannot be computed** is NaN, never a made-up number: an interval needs at least two goals
(with one goal every resample is that goal: a zero-width interval would be a lie); a ratio is
NaN in a resample whose drawn goals have no value (say, no estimate at all), and the interval
is taken over the resamples where it is defined.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from homebench.analysis.metrics import Missing, with_missing
from homebench.config import AhcDefinition
from homebench.geometry import FloatArray

LEVEL = 0.95
N_BOOT = 4000  # the expanded level reaches far into the tails (0.1 % for 5 goals)
EXACT_SIGN_FLIP_GOALS = 16  # up to 2**16 sign patterns enumerated; Monte Carlo beyond
N_SIGN_FLIPS = 20_000
_TIE = 1e-10  # a flipped total this close (relative to sum |d|) to the observed one ties


@dataclass(frozen=True)
class Interval:
    """A metric with its goal-bootstrap interval; NaN marks what cannot be computed.

    ``n_pairs``: the values it is computed from (pairs with a value; goals for a per-goal
    metric like RR). ``n_goals``: the goals those values belong to; ``lo`` and ``hi`` are NaN
    when it is below 2.
    """

    estimate: float
    lo: float
    hi: float
    n_pairs: int
    n_goals: int

    def transformed(self, f: Callable[[float], float], increasing: bool = True) -> Interval:
        """The interval of ``f(metric)`` for a monotone ``f`` (percentile intervals map
        exactly); a decreasing ``f`` swaps the bounds."""
        lo, hi = (self.lo, self.hi) if increasing else (self.hi, self.lo)
        return replace(self, estimate=float(f(self.estimate)), lo=float(f(lo)), hi=float(f(hi)))


@dataclass(frozen=True)
class Replicates:
    """A metric on the sample (``estimate``) and on each resample (``values``, shape
    (n_boot,), NaN where the resample leaves it undefined)."""

    estimate: float
    values: FloatArray
    n_pairs: int
    n_goals: int

    def interval(self, level: float = LEVEL) -> Interval:
        return intervals([self], level)[0]


class GoalResampler:
    """The goal bootstrap of one set of pairs: which goal each pair belongs to, and how often
    each goal is drawn in each resample.

    ``goal``: the goal of each pair, integers, shape (n_pairs,) or (n_pairs, k) (a label
    tuple per row, e.g. (seed, i, j)). Attributes: ``n_goals``, ``index`` ((n_pairs,) the
    goal of each pair, numbered in sorted label order) and ``counts`` ((n_boot, n_goals) draws
    per goal; every row sums to n_goals). The same labels and ``seed`` give the same counts
    whatever the order of the rows.
    """

    def __init__(self, goal: ArrayLike, n_boot: int = N_BOOT, seed: int = 0) -> None:
        self.index, self.n_goals = row_codes(goal)
        n = self.n_goals
        # n goals drawn with replacement per resample, counted per goal (multinomial counts)
        drawn = np.random.default_rng(seed).integers(0, max(n, 1), (n_boot, n))
        drawn += n * np.arange(n_boot)[:, None]
        self.counts = np.bincount(drawn.ravel(), minlength=n_boot * n).reshape(n_boot, n)
        self._weights = self.counts.astype(np.float64)

    def goal_sums(self, values: ArrayLike) -> FloatArray:
        """Sum of ``values`` (n_pairs,) per goal, shape (n_goals,), independent of row order."""
        v = np.asarray(values, dtype=np.float64)
        order = np.lexsort((v, self.index))
        return np.bincount(self.index[order], weights=v[order], minlength=self.n_goals)

    def means(self, values: ArrayLike, groups: ArrayLike | None = None) -> list[Replicates]:
        """Mean of ``values`` (n_pairs,) over the pairs with a finite value in each row of
        ``groups`` ((k, n_pairs) bool, e.g. distance bins; default: one group of all pairs), on
        the sample and on every resample; one :class:`Replicates` per group.

        Pooled over pairs (sum over sum), so a goal with more pairs weighs more, as in the
        metric computed without resampling. Pairs are summed per goal in sorted value order,
        so the sums do not depend on the row order (left-out pairs add exact zeros).
        """
        v = np.asarray(values, dtype=np.float64)
        finite = np.isfinite(v)
        use = finite[None] if groups is None else np.asarray(groups, dtype=bool) & finite
        order = np.lexsort((v, self.index))
        index, filled, use = self.index[order], np.where(finite, v, 0.0)[order], use[:, order]
        num = np.stack([np.bincount(index, u * filled, self.n_goals) for u in use], axis=1)
        den = np.stack([np.bincount(index, u.astype(float), self.n_goals) for u in use], axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            values_boot = (self._weights @ num) / (self._weights @ den)  # (n_boot, k)
            estimate = num.sum(axis=0) / den.sum(axis=0)
        n_goals = np.count_nonzero(den, axis=0)
        return [
            Replicates(float(estimate[k]), values_boot[:, k], int(use[k].sum()), int(n_goals[k]))
            for k in range(len(use))
        ]

    def mean(self, values: ArrayLike, where: ArrayLike | None = None) -> Replicates:
        """:meth:`means` of the pairs in ``where`` ((n_pairs,) bool; default all)."""
        return self.means(values, None if where is None else np.asarray(where)[None])[0]


def row_codes(labels: ArrayLike) -> tuple[np.ndarray, int]:
    """Number the distinct rows of integer ``labels`` (n,) or (n, k) in lexicographic order:
    the code of each row, shape (n,), and the number of distinct rows."""
    rows = np.asarray(labels, dtype=np.int64)
    rows = rows[:, None] if rows.ndim == 1 else rows
    code = np.zeros(len(rows), np.int64)
    for column in rows.T:  # codes stay below n_rows**2: no overflow
        values, inverse = np.unique(column, return_inverse=True)
        code = np.unique(code * len(values) + inverse, return_inverse=True)[1].reshape(-1)
    return code, int(code.max()) + 1 if code.size else 0


@cache
def expanded_level(level: float, n_goals: int) -> float:
    """The percentile level that gives an interval of nominal ``level`` for ``n_goals`` >= 2
    clusters (Hesterberg 2015): ``2 Phi(sqrt(n / (n - 1)) t_{n-1, (1 + level) / 2}) - 1``.
    (``scipy.special``'s t quantile and normal CDF are what ``scipy.stats`` calls for them;
    importing ``scipy.stats`` costs a run's process most of a second.)"""
    t = special.stdtrit(n_goals - 1, (1 + level) / 2)
    return float(2 * special.ndtr(np.sqrt(n_goals / (n_goals - 1)) * t) - 1)


def percentile_intervals(
    values: ArrayLike, n_goals: ArrayLike, level: float = LEVEL
) -> tuple[FloatArray, FloatArray]:
    """Expanded percentile intervals of bootstrap ``values`` (n_boot, k), one per column of
    a metric over ``n_goals`` (k,) goals: lo and hi, shape (k,). A column with fewer than 2
    goals or no finite value gets NaN. Quantiles interpolate linearly between order
    statistics of the finite values (numpy's default method)."""
    v = np.asarray(values, dtype=np.float64)
    v = np.sort(np.where(np.isfinite(v), v, np.nan), axis=0)  # +-inf as NaN: last, unused
    last = np.isfinite(v).sum(axis=0) - 1
    goals = np.asarray(n_goals)
    valid = (goals >= 2) & (last >= 0)
    q = np.array(
        [expanded_level(level, int(n)) if ok else 0.0 for n, ok in zip(goals, valid, strict=True)]
    )
    last, columns = np.maximum(last, 0), np.arange(v.shape[1])
    bounds = []
    for p in ((1 - q) / 2, (1 + q) / 2):
        position = p * last
        below = np.floor(position).astype(np.int64)
        above = np.minimum(below + 1, last)
        low, high = v[below, columns], v[above, columns]
        bounds.append(np.where(valid, low + (position - below) * (high - low), np.nan))
    return bounds[0], bounds[1]


def intervals(replicates: list[Replicates], level: float = LEVEL) -> list[Interval]:
    """The interval of each metric in ``replicates`` (same number of resamples each)."""
    if not replicates:
        return []
    values = np.column_stack([r.values for r in replicates])
    lo, hi = percentile_intervals(values, [r.n_goals for r in replicates], level)
    return [
        Interval(r.estimate, float(lo[k]), float(hi[k]), r.n_pairs, r.n_goals)
        for k, r in enumerate(replicates)
    ]


def mean_intervals(
    values: ArrayLike,
    resampler: GoalResampler,
    groups: ArrayLike | None = None,
    level: float = LEVEL,
) -> list[Interval]:
    """Goal-bootstrap intervals of the pooled mean of ``values`` (n_pairs,; NaN left out)
    over each group of pairs (``groups``: (k, n_pairs) bool; default all pairs), e.g. AE in
    radians, ``isnan(ae)`` (the share without an estimate) or per-goal RR (a row per goal)."""
    return intervals(resampler.means(values, groups), level)


def mean_interval(
    values: ArrayLike,
    resampler: GoalResampler,
    where: ArrayLike | None = None,
    level: float = LEVEL,
) -> Interval:
    """:func:`mean_intervals` of the pairs in ``where`` ((n_pairs,) bool; default all)."""
    return intervals([resampler.mean(values, where)], level)[0]


def ahc_intervals(
    ae: ArrayLike,
    resampler: GoalResampler,
    missing: Missing = "exclude",
    groups: ArrayLike | None = None,
    level: float = LEVEL,
    definition: AhcDefinition = "cos_mean_ae",
) -> list[Interval]:
    """The AHC of each group of pairs with its interval: seed 001's eq. 12, cos(mean AE) and
    the cos of the mean-AE interval (``definition="cos_mean_ae"``), or the mean of cos(AE) and
    its interval (``"mean_cos"``; see :data:`~homebench.analysis.metrics.AhcDefinition`).
    ``ae``: (n_pairs,) radians, NaN = no estimate, handled per ``missing``; ``groups`` as in
    :func:`mean_intervals`."""
    counted = with_missing(ae, missing)
    if definition == "mean_cos":
        return mean_intervals(np.cos(counted), resampler, groups, level)
    means = mean_intervals(counted, resampler, groups, level)
    return [mean.transformed(np.cos, increasing=False) for mean in means]


def ahc_interval(
    ae: ArrayLike,
    resampler: GoalResampler,
    missing: Missing = "exclude",
    where: ArrayLike | None = None,
    level: float = LEVEL,
    definition: AhcDefinition = "cos_mean_ae",
) -> Interval:
    """:func:`ahc_intervals` of the pairs in ``where`` ((n_pairs,) bool; default all)."""
    groups = None if where is None else np.asarray(where)[None]
    return ahc_intervals(ae, resampler, missing, groups, level, definition)[0]


# --------------------------------------------------------------------------- paired tests


def sign_flip_test(goal_totals: ArrayLike, n_flips: int = N_SIGN_FLIPS, seed: int = 0) -> float:
    """Two-sided p-value of the sign-flip permutation test on per-goal differences.

    ``goal_totals``: (n_goals,) the per-goal sums (or means) of a paired difference B - A.
    Null hypothesis: within a goal the labels A and B are exchangeable, so each goal's total is
    symmetric about 0; the statistic is ``|sum(goal_totals)|``. Up to
    ``EXACT_SIGN_FLIP_GOALS`` goals all 2**n sign patterns are enumerated (exact p; note the
    smallest p possible is 2 / 2**n: 0.0625 for 5 goals); beyond, ``n_flips`` random patterns
    (seeded) give ``(1 + hits) / (1 + n_flips)``. NaN without goals.
    """
    d = np.asarray(goal_totals, dtype=np.float64)
    n = d.size
    if n == 0:
        return np.nan
    observed = abs(d.sum()) - _TIE * np.abs(d).sum()
    if n <= EXACT_SIGN_FLIP_GOALS:
        patterns = (np.arange(2**n)[:, None] >> np.arange(n)) & 1
        return float(np.mean(np.abs((1 - 2 * patterns) @ d) >= observed))
    signs = np.random.default_rng(seed).choice([-1.0, 1.0], size=(n_flips, n))
    return float((1 + np.sum(np.abs(signs @ d) >= observed)) / (1 + n_flips))


def wilcoxon_test(differences: ArrayLike) -> float:
    """Two-sided p-value of the Wilcoxon signed-rank test on per-pair differences (n_pairs,).

    Treats the pairs as independent, which pairs of one goal are not: anti-conservative on a
    benchmark's pairs, shown beside the goal-level test. Differences are rounded to 1e-9
    (radians) so that equal errors tie exactly; zero differences are dropped (scipy's
    "wilcox" rule). NaN when no difference is left.
    """
    d = np.round(np.asarray(differences, dtype=np.float64), 9)
    d = d[np.isfinite(d) & (d != 0)]
    if d.size == 0:
        return np.nan
    from scipy import stats  # imported where needed: see expanded_level

    return float(stats.wilcoxon(d).pvalue)


@dataclass(frozen=True)
class McNemar:
    """McNemar's exact test on paired successes: ``only_a`` starts succeed for A alone,
    ``only_b`` for B alone, of ``n_starts``."""

    n_starts: int
    only_a: int
    only_b: int
    p_value: float


def mcnemar_exact(success_a: ArrayLike, success_b: ArrayLike) -> McNemar:
    """McNemar's exact test of two methods' success (n_starts,) bool on the same starts.

    Under the null both kinds of discordant start are equally likely, so ``only_b`` is
    Binomial(only_a + only_b, 1/2): the exact two-sided binomial test (scipy ``binomtest``).
    Without a discordant start p = 1 (no evidence either way); without starts NaN. Like
    Wilcoxon it treats the starts as independent, which starts of one goal are not.
    """
    a = np.asarray(success_a, dtype=bool)
    b = np.asarray(success_b, dtype=bool)
    only_a, only_b = int(np.sum(a & ~b)), int(np.sum(b & ~a))
    if a.size == 0:
        return McNemar(0, 0, 0, np.nan)
    from scipy import stats  # imported where needed: see expanded_level

    p = stats.binomtest(only_b, only_a + only_b).pvalue if only_a + only_b else 1.0
    return McNemar(int(a.size), only_a, only_b, float(p))


def holm(p_values: ArrayLike) -> FloatArray:
    """Holm's step-down adjusted p-values (same shape as ``p_values``, 1-D).

    NaN p-values (tests that could not be run) stay NaN and do not count as tests. The k-th
    smallest of m p-values becomes ``max_{j <= k} min(1, (m - j + 1) p_(j))``.
    """
    p = np.asarray(p_values, dtype=np.float64)
    out = np.full(p.shape, np.nan)
    valid = np.flatnonzero(~np.isnan(p))
    order = valid[np.argsort(p[valid], kind="stable")]
    m = order.size
    scaled = np.minimum(1.0, (m - np.arange(m)) * p[order])
    out[order] = np.maximum.accumulate(scaled)
    return out


@dataclass(frozen=True)
class AeComparison:
    """Method B against method A on the same pairs; differences are B - A.

    ``mean_ae``: difference of the mean AE (radians; negative: B errs less), with
    ``mean_ae_a`` and ``mean_ae_b`` on the compared pairs. ``ahc``: difference of AHC
    (positive: B better), with ``ahc_a`` and ``ahc_b``, by the AHC definition asked for.
    ``p_goal``: sign-flip test of the AE over goals (respects the clustering; also the test
    of the AHC difference); ``p_wilcoxon``: per pair (ignores it). ``n_excluded``: pairs left
    out for a missing estimate (``missing="exclude"``).
    """

    mean_ae: Interval
    ahc: Interval
    mean_ae_a: Interval
    mean_ae_b: Interval
    ahc_a: Interval
    ahc_b: Interval
    p_goal: float
    p_wilcoxon: float
    n_excluded: int


def compare_ae(
    ae_a: ArrayLike,
    ae_b: ArrayLike,
    goal: ArrayLike,
    missing: Missing = "orthogonal",
    n_boot: int = N_BOOT,
    level: float = LEVEL,
    seed: int = 0,
    definition: AhcDefinition = "cos_mean_ae",
) -> AeComparison:
    """Paired comparison of two methods' AE (radians, NaN = no estimate) on the same pairs.

    ``ae_a``, ``ae_b``, ``goal``: aligned, shape (n_pairs,) (``goal`` as in
    :class:`GoalResampler`). A pair missing an estimate in either method is compared with
    that AE counted as pi/2 (``missing="orthogonal"``, the default: every pair is compared
    and abstaining costs what a random guess costs) or left out and counted in
    ``n_excluded`` (``"exclude"``: both methods on the pairs where both estimate). The
    interval of the mean difference is a paired goal bootstrap (both methods' pairs move
    together); the goal test flips the signs of the per-goal sums of B - A (the mean
    difference's numerator, so larger goals weigh as they do in the estimate).
    """
    a, b = with_missing(ae_a, missing), with_missing(ae_b, missing)
    keep = np.isfinite(a) & np.isfinite(b)
    a, b = a[keep], b[keep]
    resampler = GoalResampler(np.asarray(goal)[keep], n_boot, seed)
    on_a, on_b, diff = resampler.mean(a), resampler.mean(b), resampler.mean(b - a)
    if definition == "mean_cos":
        cos_a, cos_b = resampler.mean(np.cos(a)), resampler.mean(np.cos(b))
        ahc_a, ahc_b = cos_a.interval(level), cos_b.interval(level)
        ahc_diff = Replicates(cos_b.estimate - cos_a.estimate, cos_b.values - cos_a.values,
                              diff.n_pairs, diff.n_goals)  # fmt: skip
    else:
        ahc_a, ahc_b = (m.interval(level).transformed(np.cos, increasing=False)
                        for m in (on_a, on_b))  # fmt: skip
        ahc_diff = Replicates(
            float(np.cos(on_b.estimate) - np.cos(on_a.estimate)),
            np.cos(on_b.values) - np.cos(on_a.values),
            diff.n_pairs,
            diff.n_goals,
        )
    return AeComparison(
        mean_ae=diff.interval(level),
        ahc=ahc_diff.interval(level),
        mean_ae_a=on_a.interval(level),
        mean_ae_b=on_b.interval(level),
        ahc_a=ahc_a,
        ahc_b=ahc_b,
        p_goal=sign_flip_test(resampler.goal_sums(b - a), seed=seed),
        p_wilcoxon=wilcoxon_test(b - a),
        n_excluded=int(np.sum(~keep)),
    )


@dataclass(frozen=True)
class RrComparison:
    """Method B against method A on the same return-ratio starts; differences are B - A.

    ``rr``: difference of RR (the mean over goals of per-goal RR, as in the tables), with
    ``rr_a`` and ``rr_b``; ``p_goal``: sign-flip test over the per-goal RR differences;
    ``mcnemar``: McNemar's exact test over the starts (ignores the clustering).
    """

    rr: Interval
    rr_a: Interval
    rr_b: Interval
    p_goal: float
    mcnemar: McNemar


def compare_rr(
    success_a: ArrayLike,
    success_b: ArrayLike,
    goal: ArrayLike,
    n_boot: int = N_BOOT,
    level: float = LEVEL,
    seed: int = 0,
) -> RrComparison:
    """Paired comparison of two methods' return-ratio outcomes (n_starts,) bool on the same
    starts of the same goals (``goal`` as in :class:`GoalResampler`)."""
    a = np.asarray(success_a, dtype=np.float64)
    b = np.asarray(success_b, dtype=np.float64)
    by_start = GoalResampler(goal, 1, seed)
    starts = by_start.goal_sums(np.ones_like(a))
    rr_a, rr_b = by_start.goal_sums(a) / starts, by_start.goal_sums(b) / starts
    per_goal = GoalResampler(np.arange(by_start.n_goals), n_boot, seed)
    return RrComparison(
        rr=mean_interval(rr_b - rr_a, per_goal, level=level),
        rr_a=mean_interval(rr_a, per_goal, level=level),
        rr_b=mean_interval(rr_b, per_goal, level=level),
        p_goal=sign_flip_test(rr_b - rr_a, seed=seed),
        mcnemar=mcnemar_exact(success_a, success_b),
    )
