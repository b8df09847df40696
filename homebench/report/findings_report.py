"""``homebench findings``: the papers' findings tested on run folders, as a table.

Grid runs of seed 001's experiment (methods labelled P, PN, W; conditions original-original,
original-arboreal, original-day, or other labels given) give its findings; route runs give seed
000's. Several run folders of one kind are pooled; the place of a finding is the swept style
(``styles:`` in the config), or the run folder's name for a run that sweeps none, or the world
style of a route run's config.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from homebench.errors import DataError
from homebench.evaluation.findings import (
    ALPHA,
    PAPER_ROLES,
    SiftRoles,
    findings_table,
    route_findings,
    sift_findings,
)
from homebench.experiments.route.config import KLT_SECTOR
from homebench.report.route_report import load_route_run
from homebench.report.run_data import grid_run, read_run_info
from homebench.report.tables import FIXED0, FIXED2, FIXED3, TableView, make_view


def _grid_tables(run_dirs: Sequence[Path]) -> tuple[pd.DataFrame, pd.DataFrame]:
    pairs, starts = [], []
    for run_dir in run_dirs:
        tables = grid_run(read_run_info(run_dir)).tables
        if tables.pairs.empty:
            raise DataError(f"{run_dir}: the run has no results")
        place = tables.pairs["style"].astype("object")
        if place.isna().all():  # no swept style: the run is the place
            tables.pairs["style"] = Path(run_dir).name
            tables.rr_starts["style"] = Path(run_dir).name
        pairs.append(tables.pairs)
        starts.append(tables.rr_starts)
    return pd.concat(pairs, ignore_index=True), pd.concat(starts, ignore_index=True)


def _route_table(run_dirs: Sequence[Path]) -> pd.DataFrame:
    frames = []
    for run_dir in run_dirs:
        run = load_route_run(read_run_info(run_dir))
        world = run.config.world
        frame = pd.DataFrame([trial.summary for trial in run.trials])
        # Seed 000's findings are klt-sector's: other methods of the run are left out.
        klt = [label for label, name, _ in run.config.method_points() if name == KLT_SECTOR]
        frame = frame[frame["method"].isin(klt)] if "method" in frame else frame
        frame.insert(0, "seed", world.seed)
        frame.insert(0, "style", world.style if run.config.database is None else run_dir.name)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def findings_of_runs(
    run_dirs: Sequence[Path], roles: SiftRoles = PAPER_ROLES, alpha: float = ALPHA
) -> pd.DataFrame:
    """The findings table (:func:`~homebench.evaluation.findings.findings_table`) of run
    folders, all grid runs or all route runs."""
    kinds = {read_run_info(run_dir).kind for run_dir in run_dirs}
    if len(kinds) > 1:
        raise DataError("findings: give run folders of one kind (grid runs or route runs)")
    if kinds == {"route"}:
        return findings_table(route_findings(_route_table(run_dirs), alpha))
    pairs, starts = _grid_tables(run_dirs)
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
    return findings_table(sift_findings(pairs, starts, roles, alpha))


def findings_view(table: pd.DataFrame, alpha: float = ALPHA) -> TableView:
    """The findings table for printing: place, finding, effect with its 95 % interval, unit,
    clusters, Holm-corrected p and verdict."""
    frame = pd.DataFrame(
        {
            "place": table["place"],
            "finding": table["statement"],
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
    return make_view(
        "findings", title, frame, {"effect": FIXED2, "clusters": FIXED0, "p (Holm)": FIXED3}
    )
