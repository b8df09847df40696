"""``homebench findings``: the papers' findings tested on run folders, as a table.

Grid runs of seed 001's experiment (methods labelled P, PN, W; conditions original-original,
original-arboreal, original-day, or other labels given) give its findings; route runs give seed
000's. Several run folders of one kind are pooled; the place of a finding is the swept style
(``styles:`` in the config), or the run's label (its folder's name, see
:func:`~homebench.report.run_set.run_labels`) for a grid run that sweeps none, or the world
style of a route run's config. Each run's worlds are its own units of replication.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from homebench.analysis.findings import (
    ALPHA,
    PAPER_ROLES,
    SiftRoles,
    findings_table,
    route_findings,
    sift_findings,
)
from homebench.analysis.tables import world_codes
from homebench.errors import DataError
from homebench.experiments.route.config import KLT_SECTOR
from homebench.report.route_report import load_route_run
from homebench.report.run_data import grid_run, read_run_info
from homebench.report.run_set import missing_results, run_labels
from homebench.report.tables import FIXED0, FIXED2, FIXED3, MISSING_TEXT, TableView, make_view


@dataclass(frozen=True)
class Findings:
    """The findings ``table`` of run folders
    (:func:`~homebench.analysis.findings.findings_table`) and ``warnings``: one line per job
    or trial of theirs without a result (the findings rest on the others)."""

    table: pd.DataFrame
    warnings: list[str]


def _grid_tables(run_dirs: Sequence[Path]) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """The pairs and return-ratio starts of grid runs, each row with its ``world`` (a run's
    swept world: runs never share one) and ``place`` (the swept style; for a run that sweeps
    none, the run's label), and the runs' missing jobs (:func:`missing_results`). DataError
    for a run without results, or for runs that hold the same pairs of the same images in
    one place (a goal pooled twice would count as two)."""
    pairs, starts = [], []
    labels = run_labels(run_dirs)
    runs = [grid_run(read_run_info(run_dir)) for run_dir in run_dirs]
    for k, (run_dir, label, run) in enumerate(zip(run_dirs, labels, runs, strict=True)):
        tables = run.tables
        if tables.pairs.empty:
            raise DataError(f"{run_dir}: the run has no results")
        pairs.append(_placed(tables.pairs, k, label))
        starts.append(_placed(tables.rr_starts, k, label))
    both = pd.concat([*pairs, *starts], ignore_index=True)["world"]
    codes = dict(zip(both, pd.factorize(both, sort=True)[0], strict=True))
    pairs_table, starts_table = (
        pd.concat(frames, ignore_index=True).assign(world=lambda f: f["world"].map(codes))
        for frames in (pairs, starts)
    )
    _refuse_repeated_pairs(pairs_table)
    return pairs_table, starts_table, missing_results(runs, labels)


def _placed(frame: pd.DataFrame, run: int, label: str) -> pd.DataFrame:
    """``frame`` of run number ``run`` with its ``run`` label, ``world`` key (text) and
    ``place``."""
    style = frame["style"].astype("object")
    return frame.assign(
        run=label,
        world=[f"{run}/{code}" for code in world_codes(frame)],
        place=style.where(style.notna(), label),
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


def _route_table(run_dirs: Sequence[Path]) -> tuple[pd.DataFrame, list[str]]:
    """The klt-sector trials of route runs (seed 000's findings are klt-sector's: other
    methods of a run are left out) and one line per trial without a result; DataError when no
    run holds one."""
    frames, others, warnings = [], set(), []
    for k, (run_dir, label) in enumerate(zip(run_dirs, run_labels(run_dirs), strict=True)):
        run = load_route_run(read_run_info(run_dir))
        warnings += [f"{label}: {line}" for line in run.warnings]
        world = run.config.world
        frame = pd.DataFrame([trial.summary for trial in run.trials])
        points = run.config.method_points()
        klt = [entry for entry, name, _ in points if name == KLT_SECTOR]
        others.update(entry for entry, name, _ in points if name != KLT_SECTOR)
        frame = frame[frame["method"].isin(klt)] if "method" in frame else frame
        frame.insert(0, "world", k)  # a route run drives in one world
        frame.insert(0, "place", world.style if run.config.database is None else label)
        frames.append(frame)
    table = pd.concat(frames, ignore_index=True)
    if table.empty:
        raise DataError(
            f"findings: seed 000's route findings are about {KLT_SECTOR}, and no finished "
            f"trial of the runs used it (methods: {', '.join(sorted(others))}); compare the "
            "methods of a route run in its report's paired tables"
        )
    return table, warnings


def findings_of_runs(
    run_dirs: Sequence[Path], roles: SiftRoles = PAPER_ROLES, alpha: float = ALPHA
) -> Findings:
    """The findings of run folders, all grid runs or all route runs."""
    kinds = {read_run_info(run_dir).kind for run_dir in run_dirs}
    if len(kinds) > 1:
        raise DataError("findings: give run folders of one kind (grid runs or route runs)")
    if kinds == {"route"}:
        trials, warnings = _route_table(run_dirs)
        return Findings(findings_table(route_findings(trials, alpha)), warnings)
    pairs, starts, warnings = _grid_tables(run_dirs)
    labels = set(pairs["method"])
    absent = [label for label in (roles.p, roles.pn, roles.w) if label not in labels]
    if absent:
        raise DataError(
            f"findings: no method labelled {absent[0]!r} in the runs (labels: "
            f"{', '.join(sorted(labels))}); name seed 001's roles with --p, --pn, --w"
        )
    conditions = set(pairs["condition"])
    absent = [c for c in roles.conditions if c not in conditions]
    if absent:
        raise DataError(
            f"findings: no condition {absent[0]!r} in the runs (conditions: "
            f"{', '.join(sorted(conditions))}); name them with --original, --arboreal, --day"
        )
    return Findings(findings_table(sift_findings(pairs, starts, roles, alpha)), warnings)


#: The findings view's note on the ``missing`` column.
MISSING_NOTE = (
    "pairs without estimate: how an AE finding counts a pair for which a method gave no "
    "estimate; each is tested both ways: as 90 deg (a random guess, so that abstaining gains "
    "nothing) and left out (the paper's reading). A finding that holds only when they are left "
    "out rests on the method's abstentions. --: not an AE finding (a return-ratio start without "
    "an estimate fails)."
)


def findings_view(table: pd.DataFrame, alpha: float = ALPHA) -> TableView:
    """The findings table for printing: place, finding, how a pair without an estimate counts
    (when any finding is about the AE), effect with its 95 % interval, unit, clusters,
    Holm-corrected p and verdict."""
    missing = table["missing"].replace("", MISSING_TEXT)
    about_ae = bool((missing != MISSING_TEXT).any())
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
            "clusters": table["clusters"],
            "p (Holm)": table["p_holm"],
            "verdict": table["verdict"],
        }
    )
    title = (
        f"Findings of the papers (goal-level tests, Holm-corrected within each place, "
        f"alpha = {alpha:g})"
    )
    digits = {"effect": FIXED2, "clusters": FIXED0, "p (Holm)": FIXED3}
    notes = (MISSING_NOTE,) if about_ae else ()
    return make_view("findings", title, frame, digits, notes=notes)
