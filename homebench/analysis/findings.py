"""The two papers' findings, stated as claims and tested on a run's tables with uncertainty.

A claim is directional: it names an **effect** whose mean is positive when the claim holds
(e.g. "P errs less than W": W's AE minus P's, per pair). The effect's mean gets a goal-bootstrap
interval and a two-sided goal-level p-value (the exact or Monte Carlo sign-flip test of
:mod:`homebench.analysis.statistics`), Holm-corrected over the claims of one place (a world
style, or the whole run). The verdict at level ``alpha``:

- **holds**: the corrected p-value is below ``alpha`` and the effect is positive;
- **opposite**: below ``alpha`` and negative (the data say the reverse);
- **not significant**: the data cannot tell at this level.

A claim names the method labels and conditions it needs (:class:`Planned`); a place that
lacks one, or whose tables give the claim no unit (no pair 3.45 m from its goal, say), lists it
as :class:`Untestable` with the reason, and Holm counts only what was tested
(:func:`assess_place`). The runs' own claims (:mod:`homebench.analysis.user_claims`) are
planned claims too, tested against their margin (``Tested.null``) and corrected with the
papers' in their place.

A claim of *no* effect ("does not grow by more than ...") is an equivalence claim: it holds when
the whole interval lies below its bound, is opposite when the whole interval lies above it,
and is inconclusive otherwise (no p-value).

Units of replication: for grid runs the goal of a world, (world, goal_i, goal_j) — pairs of one
goal are not independent; for route runs the trial (each drives with its own noise; trials
share their world, so the interval speaks for that world's place, not for all places); for
closed-loop runs' claims the goal when the trials reach several, else the trial
(:func:`~homebench.analysis.user_claims.trial_difference`). Tables
may say which world each row belongs to (an int column ``world``, e.g. a run and its swept
style and seed) and where its findings are tested (a column ``place``, Holm within each);
without them the swept (style, seed) is the world and the style the place (see
:func:`with_places`).

Missing estimates: every AE claim of seed 001 is tested twice, with a pair without an estimate
entering as 90 deg (what a random guess costs, so a method cannot win by abstaining) and left
out (the paper's AHC, which lets an abstaining method look better): a finding that holds only
one way says how much it rests on abstentions. Pairs that failed (an ``error``) are left out of
every effect.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd

from homebench.analysis.metrics import Missing, with_missing
from homebench.analysis.statistics import (
    LEVEL,
    N_BOOT,
    GoalResampler,
    Interval,
    Replicates,
    holm,
    sign_flip_test,
)
from homebench.analysis.tables import world_codes
from homebench.hashing import derived_seed

Verdict = Literal["holds", "opposite", "not significant", "inconclusive"]
ALPHA = 0.05
PAIR_KEY = ["world", "goal_i", "goal_j", "current_i", "current_j"]
#: Distances of seed 001's far-range finding (Fig. 9: 360 and 390 cm bins), metres.
FAR_RANGE_M = 3.45
#: Seed 000's "accuracy does not depend on the distance travelled", as a bound on the growth
#: of the final visual error: 1 mm per metre of route (1 cm after 10 m, the paper's
#: sub-centimetre accuracy).
FLAT_SLOPE_CM_PER_M = 0.1


@dataclass(frozen=True)
class Claim:
    """A finding of a paper: ``key`` (short id), ``statement`` (what holds when the effect is
    positive), ``source`` (where the paper says it), ``unit`` (of the effect) and, for an AE
    claim, how a pair without an estimate enters it (``missing``: "as 90 deg" or "left out")."""

    key: str
    statement: str
    source: str
    unit: str
    missing: str = ""


#: How each way of an AE claim counts a pair without an estimate, and its key's suffix.
AE_WAYS: tuple[tuple[Missing, str, str], ...] = (
    ("orthogonal", "as 90 deg", ""),
    ("exclude", "left out", " (missing left out)"),
)


@dataclass(frozen=True)
class Finding:
    """A claim tested in one ``place``: the effect's interval, p-values and verdict."""

    claim: Claim
    place: str
    effect: Interval
    p_value: float
    p_holm: float
    verdict: Verdict


@dataclass(frozen=True)
class SiftRoles:
    """How a run names seed 001's methods and conditions (labels in its config)."""

    p: str = "P"
    pn: str = "PN"
    w: str = "W"
    original: str = "original-original"
    arboreal: str = "original-arboreal"
    day: str = "original-day"

    @property
    def conditions(self) -> tuple[str, str, str]:
        return self.original, self.arboreal, self.day


#: The labels of ``configs/sift_paper.yaml``.
PAPER_ROLES = SiftRoles()


@dataclass(frozen=True)
class Tested:
    """An effect before the correction: interval, p-value (NaN: equivalence claim), the
    effect's value under the null hypothesis (``null``: the claim's margin) and, for an
    equivalence claim, its bound."""

    claim: Claim
    effect: Interval
    p_value: float
    bound: float | None = None
    null: float = 0.0


#: A test of a claim on one place's pairs and return-ratio starts, at a level, with n_boot.
ClaimTest = Callable[[pd.DataFrame, pd.DataFrame, float, int], Tested]


@dataclass(frozen=True)
class Planned:
    """A claim before the data: the method ``labels`` and ``conditions`` it needs, how it is
    tested (``test``) and why a place that has them may still give it no unit (``empty``)."""

    claim: Claim
    labels: tuple[str, ...]
    conditions: tuple[str, ...]
    test: ClaimTest
    empty: str = "no pair the methods share"


@dataclass(frozen=True)
class Untestable:
    """A claim that could not be tested in ``place``, and why (a missing method, condition, or
    no unit)."""

    place: str
    key: str
    reason: str


@dataclass(frozen=True)
class Assessment:
    """What was ``found`` (tested, judged) and what was ``untestable``."""

    found: list[Finding]
    untestable: list[Untestable]


# ---------------------------------------------------------------- effects


def effect_of(
    claim: Claim,
    values: np.ndarray,
    labels: np.ndarray,
    level: float,
    n_boot: int,
    null: float = 0.0,
) -> Tested:
    """The mean of per-unit ``values`` (n,) over clusters ``labels`` (n, k), tested against
    ``null`` (sign flips of the goal sums of ``values - null``)."""
    keep = np.isfinite(values)
    values, labels = values[keep], labels[keep]
    seed = derived_seed("finding", claim.key)
    resampler = GoalResampler(labels, n_boot, seed)
    interval = resampler.mean(values).interval(level)
    shifted = resampler.goal_sums(values - null)
    p = sign_flip_test(shifted, seed=seed) if len(values) else math.nan
    return Tested(claim, interval, p, null=null)


def by_pair(pairs: pd.DataFrame, condition: str, method: str, column: str) -> pd.Series:
    """``column`` (float) per pair key of one condition and method; failed pairs left out."""
    rows = pairs[(pairs["condition"] == condition) & (pairs["method"] == method)]
    if "error" in rows.columns:
        rows = rows[rows["error"].isna()]
    keys = rows[PAIR_KEY].astype(np.int64)
    values = rows[column].to_numpy(dtype=float)
    return pd.Series(values, index=pd.MultiIndex.from_frame(keys), name=f"{method}.{column}")


def ae_by_pair(pairs: pd.DataFrame, condition: str, method: str, missing: Missing) -> pd.Series:
    """AE in degrees per pair key of one condition and method, a missing estimate as 90 deg
    or NaN (left out by the effect) as ``missing`` says."""
    ae = by_pair(pairs, condition, method, "ae")
    return pd.Series(np.degrees(with_missing(ae.to_numpy(), missing)), index=ae.index)


def aligned(series: list[pd.Series]) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The series on their common keys: values, goal labels (n, 3) and the keys (n, 5)."""
    frame = pd.concat(series, axis=1, join="inner").sort_index()
    keys = np.array(frame.index.tolist(), dtype=np.int64).reshape(-1, len(PAIR_KEY))
    return [frame.iloc[:, k].to_numpy() for k in range(len(series))], keys[:, :3], keys


def _success_by_goal(starts: pd.DataFrame, condition: str, method: str) -> pd.Series:
    """Return ratio per goal (seed, goal_i, goal_j) of one condition and method."""
    rows = starts[(starts["condition"] == condition) & (starts["method"] == method)]
    success = rows["success"].astype(float)
    return success.groupby([rows[c] for c in PAIR_KEY[:3]]).mean().rename(method)


def rr_difference(
    starts: pd.DataFrame, condition: str, a: str, b: str
) -> tuple[np.ndarray, np.ndarray]:
    """Per goal that both methods walked under ``condition``: RR of ``a`` minus RR of ``b``
    (n_goals,) and the goals' labels (n_goals, 3)."""
    frame = pd.concat(
        [_success_by_goal(starts, condition, a), _success_by_goal(starts, condition, b)],
        axis=1,
        join="inner",
    )
    labels = np.array(frame.index.tolist(), dtype=np.int64).reshape(-1, 3)
    return (frame.iloc[:, 0] - frame.iloc[:, 1]).to_numpy(), labels


def ae_difference(
    pairs: pd.DataFrame, condition: str, a: str, b: str, missing: Missing
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pair both methods homed under ``condition``: AE of ``b`` minus AE of ``a``
    (degrees, (n,); positive where ``a`` errs less), the goal labels (n, 3) and the pairs'
    distances (metres, (n,))."""
    series = [ae_by_pair(pairs, condition, m, missing) for m in (a, b)]
    distance = by_pair(pairs, condition, a, "distance_m")
    (ae_a, ae_b, d), labels, _ = aligned([*series, distance])
    return ae_b - ae_a, labels, d


# ---------------------------------------------------------------- seed 001


def sift_plan(roles: SiftRoles = PAPER_ROLES) -> list[Planned]:
    """Seed 001's findings with the methods and conditions each needs, in ``roles``' labels."""
    planned: list[Planned] = []

    def ae_claim(
        key: str, statement: str, source: str, unit: str, needs: tuple[tuple[str, ...], ...],
        effect: Callable[[pd.DataFrame, Missing], tuple[np.ndarray, np.ndarray]],
        empty: str = "no pair the methods share",
    ) -> None:  # fmt: skip
        """The claim tested both ways (:data:`AE_WAYS`): ``effect(pairs, missing)`` gives
        the values and their cluster labels."""
        for missing, how, suffix in AE_WAYS:
            claim = Claim(key + suffix, statement, source, unit, how)

            def test(pairs: pd.DataFrame, _: pd.DataFrame, level: float, n_boot: int,
                     claim: Claim = claim, missing: Missing = missing) -> Tested:  # fmt: skip
                return effect_of(claim, *effect(pairs, missing), level, n_boot)

            planned.append(Planned(claim, *needs, test, empty))

    def ae_less(a: str, b: str, condition: str, key: str, statement: str, source: str) -> None:
        def effect(pairs: pd.DataFrame, missing: Missing) -> tuple[np.ndarray, np.ndarray]:
            return ae_difference(pairs, condition, a, b, missing)[:2]

        ae_claim(key, statement, source, "deg of AE", ((a, b), (condition,)), effect)

    def rr_more(a: str, b: str, condition: str, key: str, statement: str, source: str) -> None:
        claim = Claim(key, statement, source, "RR")

        def test(_: pd.DataFrame, starts: pd.DataFrame, level: float, n_boot: int) -> Tested:
            return effect_of(claim, *rr_difference(starts, condition, a, b), level, n_boot)

        planned.append(Planned(claim, (a, b), (condition,), test, "no goal both walked"))

    p, pn, w = roles.p, roles.pn, roles.w
    for condition, figure in zip(roles.conditions, "abc", strict=True):
        ae_less(
            p, w, condition, f"P<W AE {condition}",
            f"{p} errs less than {w} under {condition} (P's AHC above W's)",
            f"seed 001, Fig. 9{figure}",
        )  # fmt: skip
        rr_more(
            p, w, condition, f"P>W RR {condition}",
            f"{p}'s return ratio exceeds {w}'s under {condition}",
            f"seed 001, Fig. 10{figure}",
        )  # fmt: skip
        ae_less(
            p, pn, condition, f"P<PN AE {condition}",
            f"mismatch elimination lowers the AE under {condition} ({p} below {pn})",
            f"seed 001, Fig. 9{figure}",
        )  # fmt: skip
        rr_more(
            p, pn, condition, f"P>PN RR {condition}",
            f"mismatch elimination raises the return ratio under {condition} ({p} above {pn})",
            f"seed 001, Fig. 10{figure}",
        )  # fmt: skip

    def day_effect(pairs: pd.DataFrame, missing: Missing) -> tuple[np.ndarray, np.ndarray]:
        (w0, w1, p0, p1), labels, _ = aligned(
            [ae_by_pair(pairs, c, m, missing) for m in (w, p) for c in (roles.original, roles.day)]
        )
        return (w1 - w0) - (p1 - p0), labels

    ae_claim(
        "day hits W harder",
        f"the illumination change ({roles.day}) raises {w}'s AE more than {p}'s "
        "(warping drops dramatically, P only slightly)",
        "seed 001, Fig. 9a,c and 10a,c",
        "deg of AE",
        ((w, p), (roles.original, roles.day)),
        day_effect,
    )

    def far_effect(pairs: pd.DataFrame, missing: Missing) -> tuple[np.ndarray, np.ndarray]:
        far = [ae_difference(pairs, c, w, p, missing) for c in roles.conditions]
        values = np.concatenate([v[d >= FAR_RANGE_M] for v, _, d in far])
        return values, np.concatenate([lab[d >= FAR_RANGE_M] for _, lab, d in far])

    ae_claim(
        "far range: W<P",
        f"at 360-390 cm {w} errs less than {p} (few matches there, many wrong)",
        "seed 001, Fig. 9 and section 4.4",
        "deg of AE",
        ((p, w), roles.conditions),
        far_effect,
        f"no pair {FAR_RANGE_M:g} m or more from its goal",
    )
    for method in (p, w):
        for condition in roles.conditions:

            def below_90(pairs: pd.DataFrame, missing: Missing, c: str = condition,
                         m: str = method) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
                (ae,), labels, _ = aligned([ae_by_pair(pairs, c, m, missing)])
                return 90.0 - ae, labels

            ae_claim(
                f"{method} AHC>0 {condition}",
                f"{method}'s AHC stays above 0 under {condition} (it leads towards the goal)",
                "seed 001, section 4.4",
                "deg below 90",
                ((method,), (condition,)),
                below_90,
                "no pair with a result",
            )
    return planned


# ---------------------------------------------------------------- seed 000


def _slope_replicates(x: np.ndarray, y: np.ndarray, resampler: GoalResampler) -> Replicates:
    """Least-squares slope of y on x on the sample and every resample of the units."""
    weights = resampler.counts.astype(np.float64)
    idx = resampler.index

    def sums(v: np.ndarray) -> np.ndarray:
        return np.bincount(idx, weights=v, minlength=resampler.n_goals)

    n, sx, sy = sums(np.ones_like(x)), sums(x), sums(y)
    sxx, sxy = sums(x * x), sums(x * y)

    def slope(w: np.ndarray) -> np.ndarray:
        wn, wx, wy, wxx, wxy = (w @ s for s in (n, sx, sy, sxx, sxy))
        with np.errstate(invalid="ignore", divide="ignore"):
            return (wn * wxy - wx * wy) / (wn * wxx - wx * wx)

    estimate = float(slope(np.ones((1, resampler.n_goals)))[0])
    return Replicates(estimate, slope(weights), len(x), resampler.n_goals)


def route_tested(routes: pd.DataFrame, level: float = LEVEL, n_boot: int = N_BOOT) -> list[Tested]:
    """Seed 000's findings on the trials ``routes`` of seed 000's method in one place (columns
    ``world``, ``trial``, ``length_m``, ``visual_error_m``, ``odometry_error_m``), tested,
    before the correction."""
    return _route_claims(routes, level, n_boot)


def _route_claims(routes: pd.DataFrame, level: float, n_boot: int) -> list[Tested]:
    trial = pd.factorize(routes["trial"])[0]
    labels = np.column_stack([routes["world"].to_numpy(dtype=np.int64), trial])
    length = routes["length_m"].to_numpy(dtype=float)
    visual = 100.0 * routes["visual_error_m"].to_numpy(dtype=float)
    odometry = 100.0 * routes["odometry_error_m"].to_numpy(dtype=float)
    tested = [
        effect_of(
            Claim(
                "visual<odometry",
                "visual homing ends nearer home than odometry-based homing",
                "seed 000, section 3 and Fig. 6",
                "cm of final error",
            ),
            odometry - visual,
            labels,
            level,
            n_boot,
        )
    ]
    resampler = GoalResampler(labels, n_boot, derived_seed("finding", "slopes"))
    grows = _slope_replicates(length, odometry, resampler).interval(level)
    claim = Claim(
        "odometry grows",
        "odometry's final error grows with the route's length",
        "seed 000, section 3",
        "cm per m",
    )
    tested.append(Tested(claim, grows, _slope_p(length, odometry, labels)))
    flat = _slope_replicates(length, visual, resampler).interval(level)
    claim = Claim(
        "visual flat",
        f"visual homing's final error grows by less than {FLAT_SLOPE_CM_PER_M * 10:g} mm per "
        "metre of route (its accuracy does not depend on the distance travelled)",
        "seed 000, abstract and section 3",
        "cm per m",
    )
    tested.append(Tested(claim, flat, math.nan, bound=FLAT_SLOPE_CM_PER_M))
    return tested


def _slope_p(x: np.ndarray, y: np.ndarray, labels: np.ndarray) -> float:
    """Two-sided p-value of a zero slope: a permutation test of y over the units (seeded)."""
    rng = np.random.default_rng(derived_seed("finding", "slope-permutation"))
    xc = x - x.mean()
    observed = abs(float(xc @ y))
    permuted = np.abs(np.array([xc @ rng.permutation(y) for _ in range(N_BOOT)]))
    return float((1 + np.sum(permuted >= observed - 1e-12)) / (1 + N_BOOT))


# ---------------------------------------------------------------- verdicts


def _judge(tested: list[Tested], place: str, alpha: float) -> list[Finding]:
    adjusted = holm([t.p_value for t in tested])
    found = []
    for t, p_holm in zip(tested, adjusted, strict=True):
        effect = t.effect
        verdict: Verdict
        if t.bound is not None:
            if effect.hi < t.bound:
                verdict = "holds"
            elif effect.lo > t.bound:
                verdict = "opposite"
            else:
                verdict = "inconclusive"
        elif p_holm < alpha and effect.estimate > t.null:
            verdict = "holds"
        elif p_holm < alpha and effect.estimate < t.null:
            verdict = "opposite"
        else:
            verdict = "not significant"
        found.append(Finding(t.claim, place, effect, t.p_value, float(p_holm), verdict))
    return found


def with_places(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with the columns ``world`` (int) and ``place`` (str) where it has none: the
    swept world (:func:`~homebench.analysis.tables.world_codes`) and its style, "all"
    without a style."""
    if "world" not in frame.columns:
        frame = frame.assign(world=world_codes(frame))
    if "place" not in frame.columns:
        style = frame["style"] if "style" in frame.columns else pd.Series(None, frame.index)
        frame = frame.assign(place=style.astype("object").where(style.notna(), "all"))
    return frame


def missing_needs(planned: Planned, labels: set[str], conditions: set[str]) -> str:
    """Why a place with method ``labels`` and ``conditions`` cannot test ``planned`` ("" when
    it has what the claim needs)."""
    absent = [label for label in planned.labels if label not in labels]
    if absent:
        return f"no method labelled {', '.join(map(repr, absent))}"
    absent = [c for c in planned.conditions if c not in conditions]
    return f"no condition {', '.join(map(repr, absent))}" if absent else ""


def assess_place(
    pairs: pd.DataFrame,
    starts: pd.DataFrame,
    planned: list[Planned],
    place: str,
    alpha: float = ALPHA,
    level: float = LEVEL,
    n_boot: int = N_BOOT,
    given: Sequence[Tested] = (),
) -> Assessment:
    """Every ``planned`` claim that one place's ``pairs`` and ``starts`` can test, tested and
    judged with the claims tested already (``given``; Holm over all of them); the others
    listed with the reason. A robot run's place passes its trials table
    (:data:`~homebench.analysis.user_claims.TRIAL_COLUMNS`) as ``pairs``."""
    labels, conditions = set(pairs["method"]), set(pairs["condition"])
    tested, untestable = list(given), []
    for item in planned:
        reason = missing_needs(item, labels, conditions)
        found = None if reason else item.test(pairs, starts, level, n_boot)
        if found is not None and found.effect.n_pairs == 0:
            reason = item.empty
        if reason:
            untestable.append(Untestable(place, item.claim.key, reason))
        else:
            tested.append(found)
    return Assessment(_judge(tested, place, alpha), untestable)


def assess_grid(
    pairs: pd.DataFrame,
    starts: pd.DataFrame,
    planned: Callable[[str], list[Planned]],
    alpha: float = ALPHA,
    level: float = LEVEL,
    n_boot: int = N_BOOT,
) -> Assessment:
    """:func:`assess_place` in every place of the tables (:func:`with_places`); ``planned``
    gives each place's claims."""
    pairs, starts = with_places(pairs), with_places(starts)
    found, untestable = [], []
    for place in sorted(pairs["place"].unique()):
        name = str(place)
        done = assess_place(
            pairs[pairs["place"] == place], starts[starts["place"] == place],
            planned(name), name, alpha, level, n_boot,
        )  # fmt: skip
        found += done.found
        untestable += done.untestable
    return Assessment(found, untestable)


def sift_findings(
    pairs: pd.DataFrame,
    rr_starts: pd.DataFrame,
    roles: SiftRoles = PAPER_ROLES,
    alpha: float = ALPHA,
    level: float = LEVEL,
    n_boot: int = N_BOOT,
) -> list[Finding]:
    """Seed 001's findings that a grid run's ``pairs`` and ``rr_starts`` tables can test,
    per style (:func:`assess_grid`)."""
    plan = sift_plan(roles)
    return assess_grid(pairs, rr_starts, lambda _: plan, alpha, level, n_boot).found


def route_findings(
    routes: pd.DataFrame, alpha: float = ALPHA, level: float = LEVEL, n_boot: int = N_BOOT
) -> list[Finding]:
    """Seed 000's findings on route runs' tables (one row per trial; ``seed`` and ``style``
    columns when several worlds are pooled), per style."""
    routes = with_places(routes)
    found = []
    for place in sorted(routes["place"].unique()):
        subset = routes[routes["place"] == place]
        found += _judge(_route_claims(subset, level, n_boot), str(place), alpha)
    return found


def findings_table(found: list[Finding]) -> pd.DataFrame:
    """One row per finding: place, claim, effect with interval, p-values, verdict."""
    columns = ["place", "finding", "statement", "source", "effect", "lo", "hi", "unit",
               "missing", "n", "clusters", "p", "p_holm", "verdict"]  # fmt: skip
    return pd.DataFrame(
        [
            {
                "place": f.place,
                "finding": f.claim.key,
                "statement": f.claim.statement,
                "source": f.claim.source,
                "effect": f.effect.estimate,
                "lo": f.effect.lo,
                "hi": f.effect.hi,
                "unit": f.claim.unit,
                "missing": f.claim.missing,
                "n": f.effect.n_pairs,
                "clusters": f.effect.n_goals,
                "p": f.p_value,
                "p_holm": f.p_holm,
                "verdict": f.verdict,
            }
            for f in found
        ],
        columns=columns,
    )
