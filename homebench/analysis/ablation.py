"""Which factor of a generated world a result depends on: levels of a factor compared on the
same pairs.

A **level** is a grid run on worlds that differ from the reference level's in one factor (the
camera's exposure, noise, blur or tilt, or a named set of them) and in nothing else: the same
places (style, seed), grid, goals and current positions. A pair (style, seed, condition,
method, goal, current) therefore exists at every level, and its AE at a level and at the
reference are a **paired** observation: the place is the same, only the rendering differs.
Input: the levels' pair tables (and return-ratio starts) stacked with a ``level`` column
(:func:`stack_levels`), in the schema of :func:`homebench.evaluation.results.load_pairs`.

**Places.** Every style is a place; styles are pooled into a named place (:func:`with_places`,
:data:`INDOOR`) where a claim is about the factor rather than the place. A pooled place has the
goals of all its styles: narrower intervals and smaller attainable p-values (the sign-flip test
of n goals cannot go below 2 / 2**n: 0.0625 for 5 goals, 6e-5 for 15).

**Statistics** are those of :mod:`homebench.analysis.statistics`: the goal (world, goal_i,
goal_j) is the unit of replication; a level's metric has a goal-bootstrap interval; a change
between levels is the paired goal bootstrap of
:func:`~homebench.analysis.statistics.compare_ae` (both levels' pairs of a goal move together)
with the sign-flip test over goals. Each AE-based quantity is computed both ways seed 001's
findings are (:data:`~homebench.analysis.findings.AE_WAYS`): a pair without an estimate left
out (the paper's AHC) and counted as 90 deg (``AHC90``: abstaining gains nothing). p-values are
Holm-corrected within each place over every test of the table. Pairs that failed (an
``error``) are in no comparison, at any level.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from homebench.analysis.findings import (
    AE_WAYS,
    PAPER_ROLES,
    SiftRoles,
    findings_table,
    sift_findings,
)
from homebench.analysis.metrics import Missing, with_missing
from homebench.analysis.statistics import (
    LEVEL,
    N_BOOT,
    AeComparison,
    GoalResampler,
    Interval,
    ahc_interval,
    compare_ae,
    holm,
    mean_interval,
    sign_flip_test,
)
from homebench.analysis.tables import gives_directions, goal_labels, world_codes
from homebench.hashing import derived_seed

#: The styles that are rooms (every style but ``outdoor``): pooled as the place "indoor".
INDOOR = ("posters", "lab", "corridor", "arena")
#: A pair: its condition and method, then its goal (world, goal_i, goal_j) and current position.
PAIR = ["condition", "method", "world", "goal_i", "goal_j", "current_i", "current_j"]


def stack_levels(tables: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """The tables of several levels (pair tables, or return-ratio starts) as one, with a
    ``level`` column (categorical, in the mapping's order) and ``world``
    (:func:`~homebench.analysis.tables.world_codes`)."""
    frames = [t.assign(level=name) for name, t in tables.items() if not t.empty]
    stacked = pd.concat(frames, ignore_index=True)
    stacked["level"] = pd.Categorical(stacked["level"], categories=list(tables), ordered=True)
    return stacked.assign(world=world_codes(stacked))


def default_places(styles: Sequence[str]) -> dict[str, tuple[str, ...]]:
    """Every style alone, then "indoor" (the :data:`INDOOR` styles among ``styles``) when it
    pools two or more."""
    places = {style: (style,) for style in styles}
    indoor = tuple(style for style in styles if style in INDOOR)
    if len(indoor) >= 2:
        places["indoor"] = indoor
    return places


def with_places(frame: pd.DataFrame, places: Mapping[str, Sequence[str]]) -> pd.DataFrame:
    """``frame`` with a ``place`` column: its rows once for every place whose styles hold
    their style (a row of a pooled place's style appears under the style and the pool)."""
    parts = [
        frame[frame["style"].isin(list(styles))].assign(place=name)
        for name, styles in places.items()
    ]
    return pd.concat(parts, ignore_index=True)


def _usable(pairs: pd.DataFrame) -> pd.DataFrame:
    """The pairs that enter the tables: an answer (no ``error``) of a method that gives home
    directions."""
    if "error" in pairs.columns:
        pairs = pairs[pairs["error"].isna()]
    return pairs[gives_directions(pairs)]


# ---------------------------------------------------------------- each level's metrics


def level_summary(pairs: pd.DataFrame, places: Mapping[str, Sequence[str]]) -> pd.DataFrame:
    """AHC, AHC90 and mean AE per place, condition, method and level, each with its
    goal-bootstrap interval (``<metric>_lo``, ``_hi``); ``n_goals``, ``pairs`` and
    ``no_estimate_share``. AE in degrees; AHC as seed 001's eq. 12 (cos of the mean AE)."""
    rows = []
    frame = with_places(_usable(pairs), places)
    by = ["place", "condition", "method", "level"]
    for key, group in frame.groupby(by, sort=True, observed=True):
        resampler = GoalResampler(goal_labels(group), seed=derived_seed("ablation", *key))
        ae = group["ae"].to_numpy(dtype=float)
        rows.append(
            {
                **dict(zip(by, key, strict=True)),
                "n_goals": resampler.n_goals,
                "pairs": len(group),
                "no_estimate_share": float(np.mean(np.isnan(ae))),
                **_bounds("ahc", ahc_interval(ae, resampler, "exclude")),
                **_bounds("ahc90", ahc_interval(ae, resampler, "orthogonal")),
                **_bounds("mean_ae_deg", mean_interval(ae, resampler).transformed(np.degrees)),
            }
        )
    return pd.DataFrame(rows)


def _bounds(name: str, interval: Interval) -> dict[str, float]:
    return {name: interval.estimate, f"{name}_lo": interval.lo, f"{name}_hi": interval.hi}


# ---------------------------------------------------------------- changes against the reference


def _by_level(pairs: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """AE (radians, NaN: no estimate) per pair (index :data:`PAIR`) and level (columns), and
    whether the pair has an answer at that level (same shape)."""
    indexed = pairs.set_index([*PAIR, "level"])["ae"].astype(float)
    present = pd.Series(1.0, index=indexed.index).unstack("level").notna()
    return indexed.unstack("level"), present


def level_changes(
    pairs: pd.DataFrame,
    places: Mapping[str, Sequence[str]],
    reference: str,
    n_boot: int = N_BOOT,
    level: float = LEVEL,
) -> pd.DataFrame:
    """Every level against ``reference``, per place, condition and method, on the pairs both
    levels answered: a row per way of counting a missing estimate (``missing``: "left out",
    AHC; "as 90 deg", AHC90). Columns: ``ahc_reference``, ``ahc_level`` and ``change`` (level
    minus reference) with ``lo``, ``hi``; ``mean_ae_change_deg`` with its bounds; ``n_pairs``,
    ``n_goals``, ``n_excluded``; ``p`` (sign flips over goals) and ``p_holm`` (within the
    place, over every row)."""
    rows = []
    frame = with_places(_usable(pairs), places)
    for place, in_place in frame.groupby("place", sort=True):
        ae, present = _by_level(in_place)
        others = [name for name in ae.columns if name != reference]
        found = []
        for (condition, method), cell in ae.groupby(level=["condition", "method"], sort=True):
            for name in others:
                both = present.loc[cell.index, [reference, name]].all(axis=1).to_numpy()
                labels = cell.index.to_frame()[["world", "goal_i", "goal_j"]].to_numpy()[both]
                for missing, how, _ in AE_WAYS:
                    seed = derived_seed("ablation", place, condition, method, name, missing)
                    compared = compare_ae(
                        cell[reference].to_numpy()[both],
                        cell[name].to_numpy()[both],
                        labels,
                        missing,
                        n_boot,
                        level,
                        seed,
                    )
                    found.append(_change_row(place, condition, method, name, how, compared))
        adjusted = holm([row["p"] for row in found])
        rows += [row | {"p_holm": p} for row, p in zip(found, adjusted, strict=True)]
    return pd.DataFrame(rows)


def _change_row(
    place: str, condition: str, method: str, level_name: str, how: str, compared: AeComparison
) -> dict[str, object]:
    """One row of :func:`level_changes` from a :class:`~homebench.analysis.statistics.
    AeComparison` of the reference (A) and the level (B)."""
    degrees = compared.mean_ae.transformed(np.degrees)
    return {
        "place": place,
        "condition": condition,
        "method": method,
        "level": level_name,
        "missing": how,
        "ahc_reference": compared.ahc_a.estimate,
        "ahc_level": compared.ahc_b.estimate,
        "change": compared.ahc.estimate,
        "lo": compared.ahc.lo,
        "hi": compared.ahc.hi,
        **_bounds("mean_ae_change_deg", degrees),
        "n_pairs": compared.mean_ae.n_pairs,
        "n_goals": compared.mean_ae.n_goals,
        "n_excluded": compared.n_excluded,
        "p": compared.p_goal,
    }


# ---------------------------------------------------------------- findings across levels


@dataclass(frozen=True)
class Contrast:
    """A finding's effect as a weighted sum of AEs of the same pair position (degrees):
    ``terms`` of (condition, method, weight); positive when the finding holds. ``key`` is
    the finding's key in :mod:`homebench.analysis.findings`."""

    key: str
    terms: tuple[tuple[str, str, float], ...]


def sift_contrasts(roles: SiftRoles = PAPER_ROLES) -> list[Contrast]:
    """Seed 001's findings that compare methods' AE on the same pairs: P below W and P below
    PN under each condition, and the illumination change hitting W harder than P."""
    p, pn, w = roles.p, roles.pn, roles.w
    found = []
    for condition in roles.conditions:
        found.append(Contrast(f"P<W AE {condition}", ((condition, w, 1.0), (condition, p, -1.0))))
        found.append(Contrast(f"P<PN AE {condition}", ((condition, pn, 1.0), (condition, p, -1.0))))
    before, after = roles.original, roles.day
    terms = ((after, w, 1.0), (before, w, -1.0), (after, p, -1.0), (before, p, 1.0))
    return [*found, Contrast("day hits W harder", terms)]


def contrast_changes(
    pairs: pd.DataFrame,
    contrasts: Sequence[Contrast],
    places: Mapping[str, Sequence[str]],
    reference: str,
    n_boot: int = N_BOOT,
    level: float = LEVEL,
) -> pd.DataFrame:
    """Each contrast's effect at every level and its change against ``reference``, per
    place, both ways of counting a missing estimate (``missing``), on the pair positions
    where every term has an answer at both levels. Columns: ``effect`` (mean, degrees) with
    ``effect_lo``, ``effect_hi``; for levels other than the reference ``change`` with
    ``lo``, ``hi``, ``p`` and ``p_holm`` (within the place, over the changes); ``n_pairs``,
    ``n_goals``. A contrast whose terms are not in the tables is left out."""
    rows = []
    frame = with_places(_usable(pairs), places)
    for place, in_place in frame.groupby("place", sort=True):
        ae, present = _by_level(in_place)
        found = []
        for contrast in contrasts:
            for missing, how, _ in AE_WAYS:
                values = _contrast_values(ae, present, contrast, missing)
                if values is not None:
                    found += _contrast_rows(
                        values, reference, (place, contrast.key, how), n_boot, level
                    )
        adjusted = holm([row.get("p", np.nan) for row in found])
        rows += [row | {"p_holm": p} for row, p in zip(found, adjusted, strict=True)]
    return pd.DataFrame(rows)


def _contrast_values(
    ae: pd.DataFrame, present: pd.DataFrame, contrast: Contrast, missing: Missing
) -> pd.DataFrame | None:
    """The contrast in degrees per pair position (index: goal and current) and level
    (columns); NaN where a term has no answer or, left out, no estimate. None when a term's
    (condition, method) is not in ``ae``."""
    total: pd.DataFrame | None = None
    for condition, method, weight in contrast.terms:
        try:
            term = ae.xs((condition, method), level=["condition", "method"])
            has = present.xs((condition, method), level=["condition", "method"])
        except KeyError:
            return None
        counted = pd.DataFrame(with_missing(term.to_numpy(), missing), term.index, term.columns)
        part = weight * np.degrees(counted.where(has))
        total = part if total is None else total + part
    return total


def _contrast_rows(
    values: pd.DataFrame, reference: str, names: tuple[str, str, str], n_boot: int, level: float
) -> list[dict[str, object]]:
    """The rows of one contrast (``values``: degrees per pair position and level) in one
    place: its effect at each level, and each level's change against ``reference``."""
    place, key, how = names
    labels = values.index.to_frame()[["world", "goal_i", "goal_j"]].to_numpy()
    rows = []
    for name in values.columns:
        both = (values[name].notna() & values[reference].notna()).to_numpy()
        seed = derived_seed("ablation-contrast", place, key, how, name)
        resampler = GoalResampler(labels[both], n_boot, seed)
        row: dict[str, object] = {"place": place, "finding": key, "missing": how, "level": name}
        row |= _bounds("effect", resampler.mean(values[name].to_numpy()[both]).interval(level))
        if name != reference:
            change = (values[name] - values[reference]).to_numpy()[both]
            found = resampler.mean(change).interval(level)
            row |= {
                "change": found.estimate,
                "lo": found.lo,
                "hi": found.hi,
                "p": sign_flip_test(resampler.goal_sums(change), seed=seed),
            }
        rows.append(row | {"n_pairs": int(both.sum()), "n_goals": resampler.n_goals})
    return rows


def findings_by_level(
    pairs: pd.DataFrame,
    rr_starts: pd.DataFrame,
    places: Mapping[str, Sequence[str]],
    roles: SiftRoles = PAPER_ROLES,
    n_boot: int = N_BOOT,
) -> pd.DataFrame:
    """Seed 001's findings (:func:`homebench.analysis.findings.sift_findings`) at every level
    and in every place, Holm within each (level, place) as the findings command does; the
    columns of :func:`~homebench.analysis.findings.findings_table` and ``level``. Claims
    whose methods or conditions the tables do not hold are left out."""
    frames = []
    for name in pairs["level"].cat.categories:
        at = [with_places(t[t["level"] == name], places) for t in (pairs, rr_starts)]
        found = findings_table(sift_findings(*at, roles=roles, n_boot=n_boot))
        frames.append(found[found["n"] > 0].assign(level=name))
    return pd.concat(frames, ignore_index=True)
