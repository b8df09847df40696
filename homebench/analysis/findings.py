"""The two papers' findings, stated as claims and tested on a run's tables with uncertainty.

A claim is directional: it names an **effect** whose mean is positive when the claim holds
(e.g. "P errs less than W": W's AE minus P's, per pair). The effect's mean gets a goal-bootstrap
interval and a two-sided goal-level p-value (the exact or Monte Carlo sign-flip test of
:mod:`homebench.analysis.statistics`), Holm-corrected over the claims of one place (a world
style, or the whole run). The verdict at level ``alpha``:

- **holds**: the corrected p-value is below ``alpha`` and the effect is positive;
- **opposite**: below ``alpha`` and negative (the data say the reverse);
- **not significant**: the data cannot tell at this level.

A claim of *no* effect ("does not grow by more than ...") is an equivalence claim: it holds when
the whole interval lies below its bound, is opposite when the whole interval lies above it,
and is inconclusive otherwise (no p-value).

Units of replication: for grid runs the goal of a world, (world, goal_i, goal_j) — pairs of one
goal are not independent; for route runs the trial (each drives with its own noise; trials
share their world, so the interval speaks for that world's place, not for all places). Tables
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
from collections.abc import Callable
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
class _Tested:
    """An effect before the correction: interval, p-value (NaN: equivalence claim) and, for
    an equivalence claim, its bound."""

    claim: Claim
    effect: Interval
    p_value: float
    bound: float | None = None


# ---------------------------------------------------------------- effects


def _effect(
    claim: Claim, values: np.ndarray, labels: np.ndarray, level: float, n_boot: int
) -> _Tested:
    """The mean of per-unit ``values`` (n,) over clusters ``labels`` (n, k), tested."""
    keep = np.isfinite(values)
    values, labels = values[keep], labels[keep]
    seed = derived_seed("finding", claim.key)
    resampler = GoalResampler(labels, n_boot, seed)
    interval = resampler.mean(values).interval(level)
    p = sign_flip_test(resampler.goal_sums(values), seed=seed) if len(values) else math.nan
    return _Tested(claim, interval, p)


def _by_pair(pairs: pd.DataFrame, condition: str, method: str, column: str) -> pd.Series:
    """``column`` (float) per pair key of one condition and method; failed pairs left out."""
    rows = pairs[(pairs["condition"] == condition) & (pairs["method"] == method)]
    if "error" in rows.columns:
        rows = rows[rows["error"].isna()]
    keys = rows[PAIR_KEY].astype(np.int64)
    values = rows[column].to_numpy(dtype=float)
    return pd.Series(values, index=pd.MultiIndex.from_frame(keys), name=f"{method}.{column}")


def _ae_by_pair(pairs: pd.DataFrame, condition: str, method: str, missing: Missing) -> pd.Series:
    """AE in degrees per pair key of one condition and method, a missing estimate as 90 deg
    or NaN (left out by the effect) as ``missing`` says."""
    ae = _by_pair(pairs, condition, method, "ae")
    return pd.Series(np.degrees(with_missing(ae.to_numpy(), missing)), index=ae.index)


def _aligned(series: list[pd.Series]) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The series on their common keys: values, goal labels (n, 3) and the keys (n, 5)."""
    frame = pd.concat(series, axis=1, join="inner").sort_index()
    keys = np.array(frame.index.tolist(), dtype=np.int64).reshape(-1, len(PAIR_KEY))
    return [frame.iloc[:, k].to_numpy() for k in range(len(series))], keys[:, :3], keys


def _success_by_goal(starts: pd.DataFrame, condition: str, method: str) -> pd.Series:
    """Return ratio per goal (seed, goal_i, goal_j) of one condition and method."""
    rows = starts[(starts["condition"] == condition) & (starts["method"] == method)]
    success = rows["success"].astype(float)
    return success.groupby([rows[c] for c in PAIR_KEY[:3]]).mean().rename(method)


# ---------------------------------------------------------------- seed 001


def _sift_claims(
    pairs: pd.DataFrame, starts: pd.DataFrame, roles: SiftRoles, level: float, n_boot: int
) -> list[_Tested]:
    tested: list[_Tested] = []

    def ae_claim(
        key: str, statement: str, source: str, unit: str,
        effect: Callable[[Missing], tuple[np.ndarray, np.ndarray]],
    ) -> None:  # fmt: skip
        """The claim tested both ways (:data:`AE_WAYS`): ``effect(missing)`` gives the values
        and their cluster labels."""
        for missing, how, suffix in AE_WAYS:
            claim = Claim(key + suffix, statement, source, unit, how)
            tested.append(_effect(claim, *effect(missing), level, n_boot))

    def ae_less(a: str, b: str, condition: str, key: str, statement: str, source: str) -> None:
        def effect(missing: Missing) -> tuple[np.ndarray, np.ndarray]:
            (ae_a, ae_b), labels, _ = _aligned(
                [_ae_by_pair(pairs, condition, m, missing) for m in (a, b)]
            )
            return ae_b - ae_a, labels

        ae_claim(key, statement, source, "deg of AE", effect)

    def rr_more(a: str, b: str, condition: str, key: str, statement: str, source: str) -> None:
        frame = pd.concat(
            [_success_by_goal(starts, condition, a), _success_by_goal(starts, condition, b)],
            axis=1,
            join="inner",
        )
        labels = np.array(frame.index.tolist(), dtype=np.int64).reshape(-1, 3)
        claim = Claim(key, statement, source, "RR")
        values = (frame.iloc[:, 0] - frame.iloc[:, 1]).to_numpy()
        tested.append(_effect(claim, values, labels, level, n_boot))

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

    def day_effect(missing: Missing) -> tuple[np.ndarray, np.ndarray]:
        (w0, w1, p0, p1), labels, _ = _aligned(
            [_ae_by_pair(pairs, c, m, missing) for m in (w, p) for c in (roles.original, roles.day)]
        )
        return (w1 - w0) - (p1 - p0), labels

    ae_claim(
        "day hits W harder",
        f"the illumination change ({roles.day}) raises {w}'s AE more than {p}'s "
        "(warping drops dramatically, P only slightly)",
        "seed 001, Fig. 9a,c and 10a,c",
        "deg of AE",
        day_effect,
    )

    def far_effect(missing: Missing) -> tuple[np.ndarray, np.ndarray]:
        far = []
        for condition in roles.conditions:
            series = [_ae_by_pair(pairs, condition, m, missing) for m in (p, w)]
            distance = _by_pair(pairs, condition, p, "distance_m")
            (ae_p, ae_w, d), labels, _ = _aligned([*series, distance])
            far.append((ae_p - ae_w, labels, d >= FAR_RANGE_M))
        values = np.concatenate([v[m] for v, _, m in far])
        return values, np.concatenate([lab[m] for _, lab, m in far])

    ae_claim(
        "far range: W<P",
        f"at 360-390 cm {w} errs less than {p} (few matches there, many wrong)",
        "seed 001, Fig. 9 and section 4.4",
        "deg of AE",
        far_effect,
    )
    for method in (p, w):
        for condition in roles.conditions:

            def below_90(missing: Missing, c: str = condition, m: str = method) -> tuple:
                (ae,), labels, _ = _aligned([_ae_by_pair(pairs, c, m, missing)])
                return 90.0 - ae, labels

            ae_claim(
                f"{method} AHC>0 {condition}",
                f"{method}'s AHC stays above 0 under {condition} (it leads towards the goal)",
                "seed 001, section 4.4",
                "deg below 90",
                below_90,
            )
    return tested


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


def _route_claims(routes: pd.DataFrame, level: float, n_boot: int) -> list[_Tested]:
    trial = pd.factorize(routes["trial"])[0]
    labels = np.column_stack([routes["world"].to_numpy(dtype=np.int64), trial])
    length = routes["length_m"].to_numpy(dtype=float)
    visual = 100.0 * routes["visual_error_m"].to_numpy(dtype=float)
    odometry = 100.0 * routes["odometry_error_m"].to_numpy(dtype=float)
    tested = [
        _effect(
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
    tested.append(_Tested(claim, grows, _slope_p(length, odometry, labels)))
    flat = _slope_replicates(length, visual, resampler).interval(level)
    claim = Claim(
        "visual flat",
        f"visual homing's final error grows by less than {FLAT_SLOPE_CM_PER_M * 10:g} mm per "
        "metre of route (its accuracy does not depend on the distance travelled)",
        "seed 000, abstract and section 3",
        "cm per m",
    )
    tested.append(_Tested(claim, flat, math.nan, bound=FLAT_SLOPE_CM_PER_M))
    return tested


def _slope_p(x: np.ndarray, y: np.ndarray, labels: np.ndarray) -> float:
    """Two-sided p-value of a zero slope: a permutation test of y over the units (seeded)."""
    rng = np.random.default_rng(derived_seed("finding", "slope-permutation"))
    xc = x - x.mean()
    observed = abs(float(xc @ y))
    permuted = np.abs(np.array([xc @ rng.permutation(y) for _ in range(N_BOOT)]))
    return float((1 + np.sum(permuted >= observed - 1e-12)) / (1 + N_BOOT))


# ---------------------------------------------------------------- verdicts


def _judge(tested: list[_Tested], place: str, alpha: float) -> list[Finding]:
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
        elif p_holm < alpha and effect.estimate > 0:
            verdict = "holds"
        elif p_holm < alpha and effect.estimate < 0:
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


def _by_place(
    frames: list[pd.DataFrame],
    test: Callable[..., list[_Tested]],
    alpha: float,
    *args: object,
) -> list[Finding]:
    """``test`` per place (:func:`with_places`), Holm within each."""
    frames = [with_places(f) for f in frames]
    found = []
    for place in sorted(frames[0]["place"].unique()):
        subset = [f[f["place"] == place] for f in frames]
        found += _judge(test(*subset, *args), str(place), alpha)
    return found


def sift_findings(
    pairs: pd.DataFrame,
    rr_starts: pd.DataFrame,
    roles: SiftRoles = PAPER_ROLES,
    alpha: float = ALPHA,
    level: float = LEVEL,
    n_boot: int = N_BOOT,
) -> list[Finding]:
    """Seed 001's findings on a grid run's ``pairs`` and ``rr_starts`` tables, per style."""
    return _by_place([pairs, rr_starts], _sift_claims, alpha, roles, level, n_boot)


def route_findings(
    routes: pd.DataFrame, alpha: float = ALPHA, level: float = LEVEL, n_boot: int = N_BOOT
) -> list[Finding]:
    """Seed 000's findings on route runs' tables (one row per trial; ``seed`` and ``style``
    columns when several worlds are pooled), per style."""
    return _by_place([routes], _route_claims, alpha, level, n_boot)


def findings_table(found: list[Finding]) -> pd.DataFrame:
    """One row per finding: place, claim, effect with interval, p-values, verdict."""
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
        ]
    )
