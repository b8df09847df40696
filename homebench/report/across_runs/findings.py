"""``homebench findings``: the papers' findings and the runs' own claims tested on run folders.

Grid runs give seed 001's findings, route runs seed 000's: every finding whose methods and
conditions the runs have, named by role (:data:`ROLES`; by default the labels of
``configs/sift_paper.yaml`` and ``klt-sector``; ``--role`` names a label, a method's name or a
condition); the others are listed with the reason. A grid run's ``claims:`` are tested beside
them in the places of the runs that state them (Holm over both). Several run folders of one
kind are pooled; the place of a finding is the swept style (``styles:`` in the config), or the
run's label (its folder's name, see :func:`~homebench.report.across_runs.run_set.run_labels`) for a
grid
run that sweeps none, or a place by ``--pool`` or ``--place`` (:func:`run_places`), or the
world style of a route run's config. Each run's worlds are its own units of replication.

Route and closed-loop runs' ``claims:`` (``success``, ``final_error``) are tested on their
trials, paired by the trial's identity minus the method
(:func:`~homebench.analysis.user_claims.trial_difference`): a route run's beside seed 000's
findings in its place (Holm over both), a closed-loop run's alone in a place of the run's own
(its label; Holm over the run's claims), "no paper finding for closed-loop runs" in the list
of what was not tested.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import pandas as pd

from homebench.analysis.findings import (
    AE_WAYS,
    ALPHA,
    PAPER_ROLES,
    Planned,
    SiftRoles,
    Tested,
    Untestable,
    assess_grid,
    assess_place,
    findings_table,
    route_tested,
    sift_plan,
)
from homebench.analysis.tables import world_codes
from homebench.analysis.user_claims import claim_plan
from homebench.claim_spec import ClaimEntry, RecordedClaim, with_labels
from homebench.errors import ConfigError, DataError
from homebench.experiments.route.config import KLT_SECTOR, ODOMETRY
from homebench.report.across_runs.run_set import missing_results, run_labels
from homebench.report.closed_loop.report import load_closed_loop_run
from homebench.report.route.report import load_route_run
from homebench.report.run_data import RunData, grid_run, read_run_info
from homebench.report.tables import FIXED0, FIXED2, FIXED3, MISSING_TEXT, TableView, make_view

#: Seed 001's roles: a role name (``--role NAME=VALUE``) -> the field of
#: :class:`~homebench.analysis.findings.SiftRoles` it sets; methods first, then conditions.
METHOD_ROLES = {"P": "p", "PN": "pn", "W": "w"}
CONDITION_ROLES = {"original": "original", "arboreal": "arboreal", "day": "day"}
#: Seed 000's role: the method whose route trials its findings are about.
ROUTE_ROLE = "KLT"
ROLES = (*METHOD_ROLES, *CONDITION_ROLES, ROUTE_ROLE)
#: Each role's value when ``--role`` names none: the labels of ``configs/sift_paper.yaml``
#: and seed 000's method.
ROLE_DEFAULTS = {
    **{
        name: getattr(PAPER_ROLES, attr)
        for name, attr in {**METHOD_ROLES, **CONDITION_ROLES}.items()
    },
    ROUTE_ROLE: KLT_SECTOR,
}
#: How ``--pool`` groups runs into places: by world style, or all runs into one.
Pool = Literal["style", "all"]


@dataclass(frozen=True)
class Findings:
    """The findings ``table`` of run folders
    (:func:`~homebench.analysis.findings.findings_table`), ``warnings`` (one line per job or
    trial of theirs without a result: the findings rest on the others) and ``untestable``:
    the claims that could not be tested, with the reason (columns place, finding, reason)."""

    table: pd.DataFrame
    warnings: list[str]
    untestable: pd.DataFrame = field(default_factory=pd.DataFrame)
    units: str = "goals"


def _grid_tables(
    runs: Sequence[RunData], labels: Sequence[str], places: Sequence[str | None]
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The pairs and return-ratio starts of grid runs, each row with its ``world`` (a run's
    swept world: runs never share one) and ``place`` (``places``' name for the run; None: the
    swept style, or for a run that sweeps none the run's label). DataError for a run without
    results, or for runs that hold the same pairs of the same images in one place (a goal
    pooled twice would count as two)."""
    pairs, starts = [], []
    for k, (run, label, place) in enumerate(zip(runs, labels, places, strict=True)):
        tables = run.tables
        if tables.pairs.empty:
            raise DataError(f"{run.run_dir}: the run has no results")
        pairs.append(_placed(tables.pairs, k, label, place))
        starts.append(_placed(tables.rr_starts, k, label, place))
    both = pd.concat([*pairs, *starts], ignore_index=True)["world"]
    codes = dict(zip(both, pd.factorize(both, sort=True)[0], strict=True))
    pairs_table, starts_table = (
        pd.concat(frames, ignore_index=True).assign(world=lambda f: f["world"].map(codes))
        for frames in (pairs, starts)
    )
    _refuse_repeated_pairs(pairs_table)
    return pairs_table, starts_table


def _placed(frame: pd.DataFrame, run: int, label: str, place: str | None) -> pd.DataFrame:
    """``frame`` of run number ``run`` with its ``run`` label, ``world`` key (text) and
    ``place`` (``place``, or the swept style, or the run's label)."""
    style = frame["style"].astype("object")
    return frame.assign(
        run=label,
        world=[f"{run}/{code}" for code in world_codes(frame)],
        place=place if place is not None else style.where(style.notna(), label),
    )


def _refuse_repeated_pairs(pairs: pd.DataFrame) -> None:
    """DataError naming two runs that hold a pair of the same images, method and condition
    in one place."""
    same = ["place", "condition", "method", "current_database_key", "goal_database_key", "goal_i",
            "goal_j", "current_i", "current_j"]  # fmt: skip
    twice = pairs[pairs.duplicated(same, keep=False)]
    if twice.empty:
        return
    row = twice.iloc[0]
    runs = sorted(set(twice.loc[(twice[same] == row[same]).all(axis=1), "run"]))
    raise DataError(
        f"findings: runs {runs[0]} and {runs[-1]} both hold {row['method']}'s pairs of goal "
        f"({row['goal_i']}, {row['goal_j']}) under {row['condition']} in {row['place']}, on "
        "the same images; give each world once (a goal counted twice would count as two)"
    )


def _run_style(run: RunData) -> str | None:
    """The world style of a run that sweeps none: its generated databases' one style (None
    for a run of recorded databases, or of several styles)."""
    styles = {ref.world.style for ref in run.settings.databases.values() if ref.world is not None}
    absent = any(ref.world is None for ref in run.settings.databases.values())
    return styles.pop() if len(styles) == 1 and not absent else None


def run_places(
    runs: Sequence[RunData],
    labels: Sequence[str],
    pool: Pool | None = None,
    named: Mapping[str, str] | None = None,
) -> list[str | None]:
    """The place of each run's rows: ``named[label]`` where the user named it, else by
    ``pool`` ("all": one place; "style": a run's world style, its swept styles staying
    apart), else None (each swept style a place, a run that sweeps none its own). ConfigError
    for a name given to no run, or for ``pool="style"`` over a run whose style is unknown."""
    named = dict(named or {})
    unknown = sorted(set(named) - set(labels))
    if unknown:
        raise ConfigError(f"--place {unknown[0]}=...: no such run (runs: {', '.join(labels)})")
    places: list[str | None] = []
    for run, label in zip(runs, labels, strict=True):
        if label in named:
            places.append(named[label])
        elif pool == "all":
            places.append("all")
        elif pool == "style" and not run.settings.styles:
            style = _run_style(run)
            if style is None:
                raise ConfigError(
                    f"--pool style: run {label} holds no generated world of one style; give "
                    f"it a place with --place {label}=NAME"
                )
            places.append(style)
        else:
            places.append(None)
    return places


def _method_label(value: str, methods: pd.DataFrame, role: str) -> str | None:
    """The method label ``value`` names: itself when a label, else the one label whose entry
    runs the method of that name; None when neither. ConfigError when several labels run it."""
    if value in set(methods["method"]):
        return value
    named = sorted(set(methods.loc[methods["method_name"] == value, "method"]))
    if len(named) > 1:
        raise ConfigError(
            f"--role {role}={value}: {len(named)} method entries run {value} "
            f"({', '.join(named)}); give one label"
        )
    return named[0] if named else None


def sift_roles(given: Mapping[str, str], pairs: pd.DataFrame) -> SiftRoles:
    """Seed 001's roles from ``--role`` values (``given``: role name -> a method label or
    name, or a condition) over the runs' ``pairs``; a role not given keeps the paper's label.
    ConfigError for an unknown role, or a given value the runs do not have."""
    methods = pairs[["method", "method_name"]].drop_duplicates()
    conditions = set(pairs["condition"])
    chosen = {}
    for role, value in given.items():
        if role in METHOD_ROLES:
            label = _method_label(value, methods, role)
            if label is None:
                raise ConfigError(
                    f"--role {role}={value}: no method labelled or named {value!r} in the runs "
                    f"(labels: {', '.join(sorted(methods['method']))})"
                )
            chosen[METHOD_ROLES[role]] = label
        elif role in CONDITION_ROLES:
            if value not in conditions:
                raise ConfigError(
                    f"--role {role}={value}: no condition {value!r} in the runs (conditions: "
                    f"{', '.join(sorted(conditions))})"
                )
            chosen[CONDITION_ROLES[role]] = value
        elif role == ROUTE_ROLE:
            raise ConfigError(f"--role {role}: seed 000's role, for route runs (these: grid)")
        else:
            raise ConfigError(f"--role {role}: no such role (roles: {', '.join(ROLES)})")
    return SiftRoles(**chosen)


@dataclass(frozen=True)
class _RunClaim:
    """A claim of the runs: the earliest stated of equal claims, the metrics settings of the
    first run that states it, and the labels of every run that does."""

    claim: ClaimEntry
    run: Any
    runs: set[str]


def _claims(
    runs: Sequence[Any],
    labels: Sequence[str],
    claims_of: Callable[[Any], Sequence[ClaimEntry]] = lambda run: run.settings.claims,
) -> list[_RunClaim]:
    """The runs' claims (``claims_of`` a run: a grid run's settings' by default), each once."""
    found: dict[str, _RunClaim] = {}
    for run, label in zip(runs, labels, strict=True):
        for claim in claims_of(run):
            key = str(claim.content())
            earlier = found.setdefault(key, _RunClaim(claim, run, set()))
            earlier.runs.add(label)
            if _stated(claim) < _stated(earlier.claim):
                found[key] = _RunClaim(claim, earlier.run, earlier.runs)
    return list(found.values())


def _stated(claim: ClaimEntry) -> str:
    stated = claim.stated if isinstance(claim, RecordedClaim) else None
    return stated.isoformat() if stated is not None else "~"  # unrecorded: last


def _grid_findings(
    run_dirs: Sequence[Path],
    roles: Mapping[str, str],
    alpha: float,
    pool: Pool | None,
    named: Mapping[str, str],
) -> Findings:
    """:func:`findings_of_runs` of grid runs."""
    labels = run_labels(run_dirs)
    runs = [grid_run(read_run_info(run_dir)) for run_dir in run_dirs]
    places = run_places(runs, labels, pool, named)
    pairs, starts = _grid_tables(runs, labels, places)
    seed_plan = sift_plan(sift_roles(roles, pairs))
    claims = _claims(runs, labels)
    runs_of = pairs.groupby("place")["run"].agg(set).to_dict()

    def planned(place: str) -> list[Planned]:
        """Seed 001's findings and the claims of the place's runs."""
        here = runs_of.get(place, set())
        mine = [
            claim_plan(with_labels(c.claim, _names(c.run.settings)), c.run.settings.metrics)
            for c in claims
            if c.runs & here
        ]
        return [*seed_plan, *mine]

    done = assess_grid(pairs, starts, planned, alpha)
    return Findings(
        findings_table(done.found), missing_results(runs, labels), _untestable(done.untestable)
    )


def _names(config: Any) -> dict[str, str]:
    """A run config's method names by label (claims may name a method by its name)."""
    return {label: name for label, name, _ in config.method_points()}


def _untestable(items: Sequence[Untestable]) -> pd.DataFrame:
    """One row per claim not tested (an AE finding's two ways once): place, finding, reason."""
    rows = {(u.place, _base_key(u.key)): u.reason for u in items}
    return pd.DataFrame(
        [
            {"place": place, "finding": key, "reason": reason}
            for (place, key), reason in rows.items()
        ],
        columns=["place", "finding", "reason"],
    )


def _base_key(key: str) -> str:
    """A finding's key without the suffix of the way it counts a missing estimate."""
    for _, _, suffix in AE_WAYS:
        key = key.removesuffix(suffix) if suffix else key
    return key


def _route_tables(
    run_dirs: Sequence[Path], klt: str = KLT_SECTOR
) -> tuple[pd.DataFrame, pd.DataFrame, list[str], list[str], list[_RunClaim]]:
    """Of route runs: the trials of the method ``klt`` (a label, or a method's name: seed
    000's findings are klt-sector's; other methods of a run are left out of them), the trials
    table of every method and the odometry baseline
    (:data:`~homebench.analysis.user_claims.TRIAL_COLUMNS`, the runs' claims' units), one line
    per trial without a result, the labels of the methods left out of seed 000's findings and
    the runs' claims. Each row has its run's ``place``: the world style, or for a run of a
    database its label."""
    seed, every, others, warnings, runs = [], [], set(), [], []
    labels = run_labels(run_dirs)
    for k, (run_dir, label) in enumerate(zip(run_dirs, labels, strict=True)):
        run = load_route_run(read_run_info(run_dir))
        runs.append(run)
        warnings += [f"{label}: {line}" for line in run.warnings]
        place = run.config.world.style if run.config.database is None else label
        frame = pd.DataFrame([trial.summary for trial in run.trials])
        frame.insert(0, "world", k)  # a route run drives in one world
        frame.insert(0, "place", place)
        frame.insert(0, "run", label)
        every.append(_route_trials(frame, run.config.success_radius_m))
        points = run.config.method_points()
        chosen = [entry for entry, name, _ in points if klt in (entry, name)]
        others.update(entry for entry, _, _ in points if entry not in chosen)
        seed.append(frame[frame["method"].isin(chosen)] if "method" in frame else frame)
    claims = _claims(runs, labels, lambda run: run.config.claims)
    return (pd.concat(seed, ignore_index=True), pd.concat(every, ignore_index=True), warnings,
            sorted(others), claims)  # fmt: skip


def _route_trials(frame: pd.DataFrame, radius_m: float) -> pd.DataFrame:
    """A route run's trials (one row per trial and method: its summaries, with ``run``,
    ``place`` and ``world``) as a trials table, the odometry baseline of each trial a method
    labelled :data:`ODOMETRY`; a trial is its own cluster."""
    methods = frame.assign(final_error_m=frame["visual_error_m"].astype(float))
    odometry = frame.drop_duplicates("trial").assign(
        method=ODOMETRY, final_error_m=frame["odometry_error_m"].astype(float)
    )
    both = pd.concat([methods, odometry], ignore_index=True)
    unit = both["world"].astype(str) + "/" + both["trial"].astype(str)  # runs pooled: apart
    return both.assign(
        condition=both["route"],
        unit=unit,
        group=pd.factorize(unit)[0],
        success=(both["final_error_m"] <= radius_m).astype(float),
    )


def _route_findings(run_dirs: Sequence[Path], klt: str, alpha: float) -> Findings:
    """Seed 000's findings and the runs' claims on route runs, per place (Holm over both)."""
    seed, trials, warnings, others, claims = _route_tables(run_dirs, klt)
    found, untestable = [], []
    for place in sorted(set(trials["place"])):
        here = trials[trials["place"] == place]
        mine = seed[seed["place"] == place]
        given: list[Tested] = route_tested(mine) if not mine.empty else []
        if mine.empty:
            reason = (
                f"no finished trial of a method labelled or named {klt!r} (methods: "
                f"{', '.join(others)}; --role {ROUTE_ROLE}=LABEL)"
            )
            untestable.append(Untestable(str(place), "seed 000", reason))
        runs = set(here["run"])
        planned = [
            claim_plan(with_labels(c.claim, _names(c.run.config))) for c in claims if c.runs & runs
        ]
        done = assess_place(here, here.iloc[:0], planned, str(place), alpha, given=given)
        found += done.found
        untestable += done.untestable
    return Findings(findings_table(found), warnings, _untestable(untestable), units="trials")


#: Why a closed-loop run has no paper finding to test.
NO_CLOSED_LOOP_FINDING = "no paper finding for closed-loop runs"


def _closed_loop_findings(run_dirs: Sequence[Path], alpha: float) -> Findings:
    """The claims of closed-loop runs, each run a place of its own (its label; Holm over its
    claims); a trial is the unit, clustered by its goal when the paired trials reach
    several goals."""
    found, untestable, warnings = [], [], []
    for k, (run_dir, label) in enumerate(zip(run_dirs, run_labels(run_dirs), strict=True)):
        run = load_closed_loop_run(read_run_info(run_dir))
        warnings += [f"{label}: {line}" for line in run.warnings]
        frame = run.trials
        goal = frame["style"].astype(str) + "/g" + frame["goal"].astype(str)
        trials = frame.assign(
            world=k,
            condition=frame["style"],
            unit=goal + "/s" + frame["start"].astype(str),
            group=pd.factorize(goal)[0],
            final_error_m=frame["final_distance_m"].astype(float),
            success=frame["success"].astype(float),
        )
        untestable.append(Untestable(label, "papers' findings", NO_CLOSED_LOOP_FINDING))
        planned = [claim_plan(with_labels(c, _names(run.config))) for c in run.config.claims]
        done = assess_place(trials, trials.iloc[:0], planned, label, alpha)
        found += done.found
        untestable += done.untestable
    return Findings(findings_table(found), warnings, _untestable(untestable), units="trials")


def findings_of_runs(
    run_dirs: Sequence[Path],
    roles: Mapping[str, str] | SiftRoles | None = None,
    alpha: float = ALPHA,
    pool: Pool | None = None,
    places: Mapping[str, str] | None = None,
) -> Findings:
    """The findings of run folders, all grid runs or all route runs: every finding (and every
    claim of the runs' configs) whose methods and conditions they have, and the others with
    the reason. ``roles``: role name -> method label or name, or condition (:data:`ROLES`;
    a :class:`SiftRoles` gives those of seed 001 it changes); ``pool`` and ``places`` (run label ->
    place name) pool runs (:func:`run_places`)."""
    if isinstance(roles, SiftRoles):  # the roles it changes, as --role would give them
        fields = {**METHOD_ROLES, **CONDITION_ROLES}.items()
        roles = {
            name: getattr(roles, attr)
            for name, attr in fields
            if getattr(roles, attr) != getattr(PAPER_ROLES, attr)
        }
    roles = dict(roles or {})
    kinds = {read_run_info(run_dir).kind for run_dir in run_dirs}
    if len(kinds) > 1:
        raise DataError("findings: give run folders of one kind (grid, route or closed-loop runs)")
    if kinds == {"closed-loop"}:
        if roles or pool is not None or places:
            raise ConfigError(
                "--role, --pool, --place: no paper finding for closed-loop runs (their claims "
                "are tested per run)"
            )
        return _closed_loop_findings(run_dirs, alpha)
    if kinds != {"route"}:
        return _grid_findings(run_dirs, roles, alpha, pool, places or {})
    seed_001 = sorted(set(roles) - {ROUTE_ROLE})
    if seed_001:
        raise ConfigError(
            f"--role {seed_001[0]}: a role of seed 001's grid findings; these are route runs"
        )
    if pool is not None or places:
        raise ConfigError(
            "--pool, --place: route runs pool by world style already (grid runs only)"
        )
    return _route_findings(run_dirs, roles.get(ROUTE_ROLE, KLT_SECTOR), alpha)


def requirements() -> list[str]:
    """What each finding needs, one line per finding (an AE finding's two ways once), in
    role names (:data:`ROLES`), from the findings' own definitions (:func:`sift_plan`)."""
    paper = {getattr(PAPER_ROLES, attr): name for name, attr in METHOD_ROLES.items()}
    paper |= {getattr(PAPER_ROLES, attr): name for name, attr in CONDITION_ROLES.items()}
    lines = {}
    for item in sift_plan(PAPER_ROLES):
        methods = ", ".join(paper[label] for label in item.labels)
        conditions = ", ".join(paper[c] for c in item.conditions)
        key = _base_key(item.claim.key)
        lines.setdefault(key, f"{key}: {methods} under {conditions}")
    route = f"seed 000's route findings: {ROUTE_ROLE} (route runs)"
    return [*lines.values(), route]


#: The findings view's note on the ``missing`` column.
MISSING_NOTE = (
    "pairs without estimate: how an AE finding counts a pair for which a method gave no "
    "estimate; each is tested both ways: as 90 deg (a random guess, so that abstaining gains "
    "nothing) and left out (the paper's reading). A finding that holds only when they are left "
    "out rests on the method's abstentions. --: not an AE finding (a return-ratio start without "
    "an estimate fails)."
)


#: The findings view's note on the claims of the runs' configs.
CLAIMS_NOTE = (
    "claims: the runs' own (claims: in a run's config), tested beside the papers' findings and "
    "Holm-corrected with them; an AE or AHC claim counts a pair without an estimate as the "
    "run's AHC does (metrics.ahc.missing), AHC90 as 90 deg; a robot claim pairs the trials "
    "both methods drove from the same start. stated: when the run first recorded the claim, "
    "and whether results existed then."
)
CLAIM_SOURCE = "claim, stated "


def findings_view(table: pd.DataFrame, alpha: float = ALPHA, units: str = "goals") -> TableView:
    """The findings table for printing: place, finding, how a pair without an estimate counts
    (when any finding is about the AE), effect with its 95 % interval, unit, the number of
    ``units`` (goals, or robot trials) it rests on (for trials, their clusters too where
    fewer: a closed-loop claim's goals), Holm-corrected p, verdict and, when a run states
    claims, when each was stated."""
    by_trial = units == "trials"  # robot runs: the trials, and their clusters where fewer
    clustered = by_trial and bool((table["clusters"] != table["n"]).any())
    missing = table["missing"].replace("", MISSING_TEXT)
    about_ae = bool((missing != MISSING_TEXT).any())
    is_claim = table["source"].str.startswith(CLAIM_SOURCE)
    stated = table["source"].str.removeprefix(CLAIM_SOURCE).where(is_claim, "paper")
    frame = pd.DataFrame(
        {
            "place": table["place"],
            "finding": table["statement"],
            **({"pairs without estimate": missing} if about_ae else {}),
            "effect": table["effect"],
            "95 % interval": [
                f"[{FIXED2.text(lo)}, {FIXED2.text(hi)}]"
                for lo, hi in zip(table["lo"], table["hi"], strict=True)
            ],
            "unit": table["unit"],
            units: table["n"] if by_trial else table["clusters"],
            **({"clusters": table["clusters"]} if clustered else {}),
            "p (Holm)": table["p_holm"],
            "verdict": table["verdict"],
            **({"stated": stated} if is_claim.any() else {}),
        }
    )
    what = "the papers' findings and the runs' claims" if is_claim.any() else "the papers' findings"
    level = "paired over trials" if by_trial else "goal-level"
    title = f"Tests of {what} ({level}, Holm-corrected within each place, alpha = {alpha:g})"
    digits = {"effect": FIXED2, units: FIXED0, "p (Holm)": FIXED3}
    digits |= {"clusters": FIXED0} if clustered else {}
    notes = ((MISSING_NOTE,) if about_ae else ()) + ((CLAIMS_NOTE,) if is_claim.any() else ())
    return make_view("findings", title, frame, digits, notes=notes)


#: The note under the list of what could not be tested.
ROLES_NOTE = (
    "Name a finding's methods and conditions with --role ROLE=VALUE (a method's label or its "
    "name, or a condition), e.g. --role P=sift --role original=orig-orig; "
    "`homebench findings --help` lists what each finding needs."
)


def untestable_view(table: pd.DataFrame) -> TableView:
    """What could not be tested, and why: place, finding, reason; a note on ``--role`` unless
    the runs are closed-loop runs (they take no roles)."""
    title = "Not tested (the runs lack what the finding needs)"
    closed_loop = bool((table["reason"] == NO_CLOSED_LOOP_FINDING).any())
    return make_view("not_tested", title, table, {}, notes=() if closed_loop else (ROLES_NOTE,))
