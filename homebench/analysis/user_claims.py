"""A run's own claims (``claims:`` of its config) as planned claims, tested like the papers'.

Each claim's effect is signed so that it is positive when ``better`` is better: for ``ae`` and
``rotation_error`` the mean per-pair difference ``than - better`` (degrees), for ``ahc`` and
``ahc90`` the difference of the AHCs ``better - than``, for ``rr`` the mean per-goal difference
of return ratios ``better - than``. It is tested against the claim's ``margin`` (the null
hypothesis: ``better`` beats ``than`` by exactly the margin) on the pairs both methods homed
under the claim's condition (within its distance band), paired over goals: a goal-bootstrap
interval and the sign-flip test of the goal sums of ``effect - margin``
(:func:`~homebench.analysis.findings.effect_of`).

An AHC is not a mean over pairs when it is the cosine of the mean AE (seed 001's eq. 12, the
default ``metrics.ahc.definition``): there its p-value is the sign-flip test of the AE
difference when the margin is 0 (cos falls with the mean AE: the same hypothesis), and with a
margin the bootstrap's (twice the share of resamples on the far side of the margin, a
percentile test that is anti-conservative with few goals, as plain percentile intervals are).

A pair without an estimate counts as the run's AHC counts it (``metrics.ahc.missing``; left
out by default, the paper's reading) for ``ae`` and ``ahc``, and as 90 deg for ``ahc90``.

Robot runs' claims (``success``, ``final_error``) are tested on a table of trials
(:data:`TRIAL_COLUMNS`, one row per trial and method label; a route run's odometry baseline is
the label ``odometry``): the effect per trial that both methods finished from the same start
(the trial's identity minus the method, ``unit``) under the claim's condition (every trial
without one) is ``better``'s success minus ``than``'s (1, 0 or -1: the mean is the difference
of the success rates) or ``than``'s final distance to home minus ``better``'s (metres). Its
interval is a bootstrap and its p the sign-flip test of the cluster sums of ``effect -
margin`` over the clusters ``group`` gives: the goal of a closed-loop trial (trials to one
goal share its snapshot) when the paired trials reach several goals, else the trial itself
(a route run's trials each drive with their own noise: the trial is the unit, as for seed
000's findings).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from homebench.analysis.findings import (
    Claim,
    Planned,
    Tested,
    aligned,
    by_pair,
    effect_of,
    rr_difference,
)
from homebench.analysis.metrics import Missing, with_missing
from homebench.analysis.statistics import GoalResampler, Replicates, sign_flip_test
from homebench.claim_spec import ROBOT_METRICS, ClaimEntry, claim_text, stated_text
from homebench.config import MetricsConfig
from homebench.hashing import derived_seed

UNITS = {
    "ae": "deg of AE",
    "rotation_error": "deg of rotation error",
    "ahc": "AHC",
    "ahc90": "AHC",
    "rr": "RR",
    "success": "success share",
    "final_error": "m of final error",
}
#: The columns of a robot run's trials table: the method label, the condition (route name or
#: world style), the trial's identity minus the method (str), the world (int: pooled runs
#: never share one), the cluster (int: a closed-loop trial's goal, a route trial itself), the
#: final distance to home (metres) and whether the trial ended within the success radius.
TRIAL_COLUMNS = ("method", "condition", "unit", "world", "group", "final_error_m", "success")
MISSING_WORDS: dict[Missing, str] = {"orthogonal": "as 90 deg", "exclude": "left out"}


def claim_plan(claim: ClaimEntry, metrics: MetricsConfig | None = None) -> Planned:
    """``claim`` as a planned claim, tested with the run's ``metrics`` settings (a grid
    run's; robot claims need none). A robot claim's test takes the trials table
    (:data:`TRIAL_COLUMNS`) in place of the pairs."""
    metrics = metrics or MetricsConfig()
    missing: Missing = "orthogonal" if claim.metric == "ahc90" else metrics.ahc.missing
    plain = ("rr", "rotation_error", *ROBOT_METRICS)
    how = "" if claim.metric in plain else MISSING_WORDS[missing]
    text = claim_text(claim)
    record = Claim(text, text, f"claim, stated {stated_text(claim)}", UNITS[claim.metric], how)
    conditions = () if claim.condition is None else (claim.condition,)
    if claim.metric in ROBOT_METRICS:

        def on_trials(trials: pd.DataFrame, _: pd.DataFrame, level: float, n_boot: int) -> Tested:
            values, labels = trial_difference(claim, trials)
            return effect_of(record, values, labels, level, n_boot, claim.margin)

        empty = "no trial both methods finished from the same start"
        return Planned(record, (claim.better, claim.than), conditions, on_trials, empty)

    def test(pairs: pd.DataFrame, starts: pd.DataFrame, level: float, n_boot: int) -> Tested:
        if claim.metric == "rr":
            values, labels = rr_difference(starts, claim.condition, claim.better, claim.than)
            return effect_of(record, values, labels, level, n_boot, claim.margin)
        if claim.metric in ("ahc", "ahc90"):
            return _ahc_test(record, claim, pairs, missing, metrics, level, n_boot)
        values, labels = _pair_difference(claim, pairs, missing)
        return effect_of(record, values, labels, level, n_boot, claim.margin)

    empty = "no pair both methods homed" + (" in the band" if claim.band else "")
    return Planned(record, (claim.better, claim.than), conditions, test, empty)


def trial_difference(claim: ClaimEntry, trials: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Per trial unit both methods finished under the claim's condition (all without one):
    the effect (see the module docstring) and the cluster labels (n, 2): (world, goal) when
    the units reach several clusters of ``group``, else (world, unit)."""
    rows = trials if claim.condition is None else trials[trials["condition"] == claim.condition]
    column = "success" if claim.metric == "success" else "final_error_m"

    def of(label: str) -> pd.DataFrame:
        mine = rows[rows["method"] == label]
        return mine.set_index("unit")[[column, "world", "group"]].astype(float)

    than_column = of(claim.than)[[column]].rename(columns={column: f"{column}_than"})
    both = of(claim.better).join(than_column, how="inner")
    both = both[np.isfinite(both[[column, f"{column}_than"]]).all(axis=1)].sort_index()
    better, than = both[column].to_numpy(), both[f"{column}_than"].to_numpy()
    values = better - than if claim.metric == "success" else than - better
    world = both["world"].to_numpy(dtype=np.int64)
    groups = both[["world", "group"]].drop_duplicates()
    second = (
        both["group"].to_numpy(dtype=np.int64)
        if len(groups) > 1
        else pd.factorize(both.index)[0].astype(np.int64)
    )
    return values, np.column_stack([world, second]).reshape(-1, 2)


def _in_band(claim: ClaimEntry, distance: np.ndarray) -> np.ndarray:
    """Which pairs (by their distance to the goal, metres) lie in the claim's band."""
    if claim.band is None:
        return np.ones(distance.shape, bool)
    lo, hi = claim.band
    return (distance >= lo) & (distance <= hi)


def _paired(
    claim: ClaimEntry, pairs: pd.DataFrame, column: str, missing: Missing
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``column`` (radians) of ``better`` and of ``than``, (2, n), on the pairs both homed in
    the band, a missing value counted as ``missing`` says and pairs where either is then NaN
    left out; and their goal labels (n, 3)."""
    methods = (claim.better, claim.than)
    series = [by_pair(pairs, claim.condition, m, column) for m in methods]
    (better, than, distance), labels, _ = aligned(
        [*series, by_pair(pairs, claim.condition, claim.better, "distance_m")]
    )
    values = np.stack([with_missing(better, missing), with_missing(than, missing)])
    keep = _in_band(claim, distance) & np.isfinite(values).all(axis=0)
    return values[:, keep], labels[keep]


def _pair_difference(
    claim: ClaimEntry, pairs: pd.DataFrame, missing: Missing
) -> tuple[np.ndarray, np.ndarray]:
    """Per pair in the band: ``than``'s error minus ``better``'s (degrees) and goal labels."""
    if claim.metric == "ae":
        (better, than), labels = _paired(claim, pairs, "ae", missing)
    else:  # a method that reports no rotation has no rotation error: left out
        (better, than), labels = _paired(claim, pairs, "rotation_error", "exclude")
    return np.degrees(than - better), labels


def _ahc_test(
    record: Claim,
    claim: ClaimEntry,
    pairs: pd.DataFrame,
    missing: Missing,
    metrics: MetricsConfig,
    level: float,
    n_boot: int,
) -> Tested:
    """AHC of ``better`` minus AHC of ``than`` on the pairs both homed, paired over goals."""
    (ae_better, ae_than), labels = _paired(claim, pairs, "ae", missing)
    if metrics.ahc.definition == "mean_cos":
        values = np.cos(ae_better) - np.cos(ae_than)
        return effect_of(record, values, labels, level, n_boot, claim.margin)
    seed = derived_seed("finding", record.key)
    resampler = GoalResampler(labels, n_boot, seed)
    on_better, on_than = resampler.mean(ae_better), resampler.mean(ae_than)
    effect = Replicates(
        float(np.cos(on_better.estimate) - np.cos(on_than.estimate)),
        np.cos(on_better.values) - np.cos(on_than.values),
        len(labels),
        resampler.n_goals,
    )
    if not len(labels):
        p = math.nan
    elif claim.margin == 0:
        p = sign_flip_test(resampler.goal_sums(ae_than - ae_better), seed=seed)
    else:
        p = _bootstrap_p(effect.values, claim.margin)
    return Tested(record, effect.interval(level), p, null=claim.margin)


def _bootstrap_p(values: np.ndarray, null: float) -> float:
    """Two-sided percentile-bootstrap p-value of ``null``: twice the smaller count of finite
    resampled ``values`` on either side of it, plus one, over their number plus one (never
    0; at most 1)."""
    finite = values[np.isfinite(values)]
    if not len(finite):
        return math.nan
    hits = min(np.sum(finite <= null), np.sum(finite >= null))
    return float(min(1.0, 2 * (1 + hits) / (1 + len(finite))))
