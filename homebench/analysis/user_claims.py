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
from homebench.claim_spec import ClaimEntry, claim_text, stated_text
from homebench.config import MetricsConfig
from homebench.hashing import derived_seed

UNITS = {
    "ae": "deg of AE",
    "rotation_error": "deg of rotation error",
    "ahc": "AHC",
    "ahc90": "AHC",
    "rr": "RR",
}
MISSING_WORDS: dict[Missing, str] = {"orthogonal": "as 90 deg", "exclude": "left out"}


def claim_plan(claim: ClaimEntry, metrics: MetricsConfig) -> Planned:
    """``claim`` as a planned claim, tested with the run's ``metrics`` settings."""
    missing: Missing = "orthogonal" if claim.metric == "ahc90" else metrics.ahc.missing
    how = "" if claim.metric in ("rr", "rotation_error") else MISSING_WORDS[missing]
    text = claim_text(claim)
    record = Claim(text, text, f"claim, stated {stated_text(claim)}", UNITS[claim.metric], how)

    def test(pairs: pd.DataFrame, starts: pd.DataFrame, level: float, n_boot: int) -> Tested:
        if claim.metric == "rr":
            values, labels = rr_difference(starts, claim.condition, claim.better, claim.than)
            return effect_of(record, values, labels, level, n_boot, claim.margin)
        if claim.metric in ("ahc", "ahc90"):
            return _ahc_test(record, claim, pairs, missing, metrics, level, n_boot)
        values, labels = _pair_difference(claim, pairs, missing)
        return effect_of(record, values, labels, level, n_boot, claim.margin)

    empty = "no pair both methods homed" + (" in the band" if claim.band else "")
    return Planned(record, (claim.better, claim.than), (claim.condition,), test, empty)


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
