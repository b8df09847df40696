"""The statistics layer: goal-bootstrap intervals, paired tests, Holm; hand-computed cases and
simulations whose truth is known."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.analysis.metrics import ae_summary, ahc
from homebench.analysis.statistics import (
    EXACT_SIGN_FLIP_GOALS,
    GoalResampler,
    ahc_interval,
    compare_ae,
    compare_rr,
    expanded_level,
    holm,
    mcnemar_exact,
    mean_interval,
    row_codes,
    sign_flip_test,
    wilcoxon_test,
)

PAIRS_PER_GOAL = 169  # a 10 x 17 grid without the goal


def clustered_ae(
    rng: np.random.Generator, n_goals: int, goal_sd_deg: float = 5.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """AE (radians) of a method on ``n_goals`` goals x 169 pairs: a goal-level mean (goals differ
    in difficulty, sd ``goal_sd_deg``) plus pair noise (sd 3 deg). Returns (ae, goal, goal mean)."""
    goal = np.repeat(np.arange(n_goals), PAIRS_PER_GOAL)
    goal_mean = np.radians(20.0 + rng.normal(0.0, goal_sd_deg, n_goals))
    ae = goal_mean[goal] + np.radians(rng.normal(0.0, 3.0, goal.size))
    return ae, goal, goal_mean


# --------------------------------------------------------------------------- intervals


def test_two_goals_interval_spans_them_and_estimate_is_the_pooled_mean():
    goal = np.repeat([0, 1], [10, 30])
    values = np.where(goal == 0, 1.0, 3.0)
    found = mean_interval(values, GoalResampler(goal, seed=1))
    assert found.estimate == pytest.approx((10 * 1.0 + 30 * 3.0) / 40)
    # with two goals the expanded level is ~1: the interval is the range of the goal means
    assert (found.lo, found.hi) == (1.0, 3.0)
    assert (found.n_pairs, found.n_goals) == (40, 2)


def test_single_goal_gives_nan_interval_not_a_zero_width_one():
    rng = np.random.default_rng(0)
    found = mean_interval(rng.random(50), GoalResampler(np.zeros(50, int)))
    assert np.isfinite(found.estimate) and found.n_goals == 1
    assert np.isnan(found.lo) and np.isnan(found.hi)
    empty = mean_interval(np.empty(0), GoalResampler(np.empty(0, int)))
    assert np.isnan(empty.estimate) and np.isnan(empty.lo) and empty.n_goals == 0


def test_goals_without_values_do_not_count_and_undefined_resamples_are_skipped():
    goal = np.repeat([0, 1, 2], 4)
    ae = np.array([0.1] * 4 + [0.3] * 4 + [np.nan] * 4)  # goal 2 has no estimate at all
    found = mean_interval(ae, GoalResampler(goal, seed=3))
    assert (found.n_pairs, found.n_goals) == (8, 2)
    assert found.lo == pytest.approx(0.1) and found.hi == pytest.approx(0.3)
    one = mean_interval(ae, GoalResampler(goal, seed=3), where=goal != 1)
    assert one.n_goals == 1 and np.isnan(one.lo)


def test_estimates_equal_the_metrics_of_the_tables():
    rng = np.random.default_rng(1)
    ae, goal, _ = clustered_ae(rng, 5)
    ae[rng.random(ae.size) < 0.2] = np.nan
    resampler = GoalResampler(goal, seed=2)
    summary = ae_summary(ae)
    assert mean_interval(ae, resampler).estimate == pytest.approx(summary["mean_rad"], 1e-12)
    share = mean_interval(np.isnan(ae), resampler).estimate
    assert share == pytest.approx(summary["missing_share"], 1e-12)
    for missing in ("exclude", "orthogonal"):
        found = ahc_interval(ae, resampler, missing)
        assert found.estimate == pytest.approx(ahc(ae, missing), 1e-12)
        assert found.lo <= found.estimate <= found.hi
    # the AHC interval is cos of the mean-AE interval (cos decreases: bounds swap)
    mean = mean_interval(ae, resampler)
    found = ahc_interval(ae, resampler)
    assert (found.lo, found.hi) == (np.cos(mean.hi), np.cos(mean.lo))
    assert ahc_interval(ae, resampler, "orthogonal").estimate < found.estimate


def test_same_seed_same_interval_whatever_the_row_order():
    rng = np.random.default_rng(2)
    ae, goal, _ = clustered_ae(rng, 6)
    ae[::7] = np.nan
    labels = np.column_stack([np.full(goal.size, -1), goal, 3 * goal])  # (seed, i, j)
    order = rng.permutation(goal.size)
    first = ahc_interval(ae, GoalResampler(labels, seed=11))
    again = ahc_interval(ae, GoalResampler(labels, seed=11))
    permuted = ahc_interval(ae[order], GoalResampler(labels[order], seed=11))
    assert first == again == permuted
    assert first != ahc_interval(ae, GoalResampler(labels, seed=12))


def test_row_codes_number_rows_in_lexicographic_order():
    codes, n = row_codes([[1, 5], [0, 9], [1, 5], [1, 2]])
    assert n == 3 and list(codes) == [2, 0, 2, 1]
    assert row_codes(np.array([7, 3, 7]))[0].tolist() == [1, 0, 1]
    assert row_codes(np.empty((0, 3), int))[1] == 0


def test_expanded_level_widens_for_few_goals_and_fades_for_many():
    levels = [expanded_level(0.95, n) for n in (2, 5, 10, 30, 1000)]
    assert levels == sorted(levels, reverse=True)
    assert levels[1] > 0.99 and levels[-1] == pytest.approx(0.95, abs=1e-3)


@pytest.mark.parametrize(("n_goals", "low"), [(5, 0.88), (10, 0.90)])
def test_interval_covers_the_truth_about_95_percent_of_the_time(n_goals, low):
    """200 samples of ``n_goals`` goals from a population whose mean AE is known (goal means
    Gamma(4, 0.05) rad, mean 0.2; per pair an exponential error around the goal mean).

    If the coverage were exactly 95 %, the count of 200 would be Binomial(200, 0.95): sd 3.1
    intervals (1.5 %). The expanded percentile interval keeps most but not all of its nominal
    level with very few goals (about 92 % for 5 goals, 94 % for 10, measured on 1000 samples),
    so the lower bounds sit about 2 sd below those; the upper bound 0.99 catches intervals
    made far too wide. A plain percentile interval covers about 84 % with 5 goals and fails.
    """
    rng = np.random.default_rng(100 + n_goals)
    goal = np.repeat(np.arange(n_goals), PAIRS_PER_GOAL)
    covered = 0
    for k in range(200):
        goal_mean = rng.gamma(4.0, 0.05, n_goals)
        ae = rng.exponential(goal_mean[goal])
        found = mean_interval(ae, GoalResampler(goal, seed=k))
        covered += found.lo <= 0.2 <= found.hi
    assert low <= covered / 200 <= 0.99


# --------------------------------------------------------------------------- paired tests


def test_known_difference_is_significant_and_covered():
    """B's AE = A's + 5 deg, with goal-level noise (sd 1.5 deg) and pair noise (3 deg).

    10 goals: the sign-flip test can reach p = 2 / 2**10; every goal's mean difference is
    positive by more than 3 sd, so the test gives its smallest p. The interval of the mean
    difference is about +-1.5 deg wide and must cover 5 deg.
    """
    rng = np.random.default_rng(5)
    ae_a, goal, _ = clustered_ae(rng, 10)
    shift = np.radians(5.0 + rng.normal(0.0, 1.5, 10))[goal]
    ae_b = ae_a + shift + np.radians(rng.normal(0.0, 3.0, goal.size))
    found = compare_ae(ae_a, ae_b, goal, seed=1)
    assert found.p_goal == pytest.approx(2 / 2**10)
    assert found.p_wilcoxon < 1e-10
    assert found.mean_ae.lo <= np.radians(5.0) <= found.mean_ae.hi
    assert found.mean_ae.lo > 0
    assert found.ahc.hi < 0  # B errs more: lower AHC
    assert found.ahc_a.estimate == pytest.approx(ahc(ae_a))
    assert (found.mean_ae.n_pairs, found.mean_ae.n_goals, found.n_excluded) == (1690, 10, 0)


def test_same_method_with_other_seeds_is_not_significant_and_wilcoxon_is_anticonservative():
    """100 comparisons of a method with itself on other draws: the same goal means, an
    independent goal-level term (sd 2 deg: a different world seed moves whole goals) and new
    pair noise (3 deg). No real difference, so the goal-level sign-flip test must reject at
    most about 5 % (exact test: at most 5 % in expectation; 10 of 100 has probability 1 %
    under 5 %). The per-pair Wilcoxon test sees 8 x 169 pairs as independent and rejects
    most of them: the reason it is never the basis of a finding.
    """
    rng = np.random.default_rng(6)
    rejected_goal = rejected_pair = covered = 0
    for k in range(100):
        ae_a, goal, goal_mean = clustered_ae(rng, 8)
        goal_term = np.radians(rng.normal(0.0, 2.0, 8))[goal]
        ae_b = goal_mean[goal] + goal_term + np.radians(rng.normal(0.0, 3.0, goal.size))
        found = compare_ae(ae_a, ae_b, goal, seed=k)
        rejected_goal += found.p_goal < 0.05
        rejected_pair += found.p_wilcoxon < 0.05
        covered += found.mean_ae.lo <= 0.0 <= found.mean_ae.hi
    assert rejected_goal <= 10
    assert covered >= 85
    assert rejected_pair >= 50


def test_missing_estimates_compared_as_90_deg_or_excluded():
    goal = np.repeat([0, 1], 3)
    ae_a = np.array([0.1, 0.1, np.nan, 0.2, 0.2, 0.2])
    ae_b = np.array([0.1, 0.3, 0.3, np.nan, 0.2, 0.4])
    orthogonal = compare_ae(ae_a, ae_b, goal)
    assert orthogonal.n_excluded == 0 and orthogonal.mean_ae.n_pairs == 6
    expected = (0.0 + 0.2 + (0.3 - np.pi / 2) + (np.pi / 2 - 0.2) + 0.0 + 0.2) / 6
    assert orthogonal.mean_ae.estimate == pytest.approx(expected)
    excluded = compare_ae(ae_a, ae_b, goal, missing="exclude")
    assert excluded.n_excluded == 2 and excluded.mean_ae.n_pairs == 4
    assert excluded.mean_ae.estimate == pytest.approx(0.4 / 4)
    with pytest.raises(ValueError, match="missing"):
        compare_ae(ae_a, ae_b, goal, missing="drop")


@pytest.mark.parametrize(
    ("totals", "p"),
    [
        # 8 sign patterns of +-a +-b +-c; |sum| >= observed:
        ([1.0, 2.0, 3.0], 2 / 8),  # sums 6, -6 only
        ([3.0, 1.0, -1.0], 6 / 8),  # |sums| 5, 3, 3, 1, 1, 3, 3, 5 against 3
        ([1.0, 2.0, -3.0], 1.0),  # observed sum 0
        ([0.1 + 0.2, -0.3, 0.5], 6 / 8),  # |sums| 0.5 (4x, equal up to rounding), 1.1 (2x)
        ([2.0], 1.0),  # one goal: both patterns tie
    ],
)
def test_sign_flip_exact_small_cases(totals, p):
    assert sign_flip_test(totals) == pytest.approx(p)


def test_sign_flip_monte_carlo_beyond_exact_limit():
    n = EXACT_SIGN_FLIP_GOALS + 1
    d = np.random.default_rng(7).normal(0.3, 1.0, n)
    signs = 1 - 2 * ((np.arange(2**n)[:, None] >> np.arange(n)) & 1)
    exact = np.mean(np.abs(signs @ d) >= abs(d.sum()) - 1e-12)
    found = sign_flip_test(d, seed=3)
    assert found == sign_flip_test(d, seed=3)
    assert found == pytest.approx(exact, abs=0.01)  # MC sd with 20000 flips < 0.004
    assert np.isnan(sign_flip_test([]))


def test_wilcoxon_exact_small_case_and_no_difference():
    assert wilcoxon_test([1.0, 2.0, 3.0, 4.0, 5.0]) == pytest.approx(2 / 2**5)
    assert np.isnan(wilcoxon_test([0.0, 0.0]))


def test_mcnemar_exact_hand_computed():
    a = np.array([True] * 5 + [True, False] * 3)
    b = np.array([False] * 5 + [True, False] * 3)
    found = mcnemar_exact(a, b)
    assert (found.n_starts, found.only_a, found.only_b) == (11, 5, 0)
    assert found.p_value == pytest.approx(2 * 0.5**5)  # 0 of 5 discordant for B
    assert mcnemar_exact(b, a).p_value == pytest.approx(0.0625)
    one_of_five = mcnemar_exact([1, 1, 1, 1, 0], [0, 0, 0, 0, 1])
    assert one_of_five.p_value == pytest.approx(2 * 6 / 32)
    assert mcnemar_exact(a, a).p_value == 1.0
    assert np.isnan(mcnemar_exact([], []).p_value)


def test_holm_hand_computed():
    # sorted 0.005, 0.01, 0.03, 0.04 -> x4, x3, x2, x1 = 0.02, 0.03, 0.06, 0.04 -> running max
    adjusted = holm([0.01, 0.04, np.nan, 0.03, 0.005])
    np.testing.assert_allclose(adjusted, [0.03, 0.06, np.nan, 0.06, 0.02])
    np.testing.assert_allclose(holm([0.5, 0.9]), [1.0, 1.0])
    assert holm([]).size == 0


def test_compare_rr_goal_level_and_mcnemar():
    goal = np.repeat([0, 1, 2], 10)
    a = np.ones(30, bool)
    b = a.copy()
    b[:5] = False  # B fails 5 starts of goal 0
    found = compare_rr(a, b, goal, seed=2)
    assert found.rr.estimate == pytest.approx(-0.5 / 3)  # per-goal RR: 0.5, 1, 1 against 1
    assert found.rr_a.estimate == 1.0 and found.rr_b.estimate == pytest.approx(2.5 / 3)
    assert found.mcnemar.p_value == pytest.approx(0.0625)
    assert found.p_goal == 1.0  # one goal differs: every sign pattern gives |sum| 0.5
    assert found.rr.lo == pytest.approx(-0.5) and found.rr.hi == 0.0
    assert found.rr.n_goals == 3


def test_percentile_intervals_use_the_finite_values_only_and_warn_of_nothing() -> None:
    """An infinite replicate (a ratio over an empty resample) is no order statistic: -inf
    sorted first shifted every quantile, and inf - inf printed numpy's RuntimeWarning on the
    findings console."""
    import warnings

    from homebench.analysis.statistics import percentile_intervals

    finite = np.arange(1.0, 101.0)
    values = np.stack([np.r_[-np.inf, finite, np.inf], np.r_[np.nan, finite, np.nan]], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lo, hi = percentile_intervals(values, [10, 10])
        lo_all_inf, _ = percentile_intervals(np.full((5, 1), -np.inf), [10])
    assert lo[0] == lo[1] and hi[0] == hi[1]
    assert np.isnan(lo_all_inf[0])
