"""What ``homebench run`` prints at the end of a robot experiment: a route or closed-loop
run's summary, as compact as a grid run's headline (:func:`~.tables.console_summary`).

Each is a report table narrowed to the columns a reader needs first, under shorter headers
(:func:`narrowed`): a column without a value (a catchment nobody measured) or, for counts
of mishaps, without a non-zero value is left out; a missing value reads ``--`` as in the
grid headline. Every column stays in the run folder's tables.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import replace
from typing import Any

import pandas as pd

from homebench.report.closed_loop.report import summary_view
from homebench.report.route.compare import ODOMETRY, method_view
from homebench.report.tables import FIXED2, MISSING_TEXT, TableView, to_text

#: The route summary's catchment of the route-learning methods probed beside their route (the
#: mean of routes.csv's ``catchment_m`` over trials).
CATCHMENT = "catchment [m]"
#: The route summary (:func:`~.route.compare.method_view`): report header -> console header.
ROUTE_COLUMNS = {
    "method": "method",
    "trials": "trials",
    "success [%]": "success [%]",
    "final error mean [cm]": "error [cm]",
    "final error median [cm]": "median",
    "path / route length": "path/route",
    CATCHMENT: CATCHMENT,
}
#: The closed-loop summary (:func:`~.closed_loop.report.summary_view`): report header ->
#: console header.
CLOSED_LOOP_COLUMNS = {
    "style": "style",
    "method": "method",
    "success rate": "success",
    "catchment [m^2]": "catchment [m^2]",
    "final distance, median [cm]": "final [cm]",
    "path ratio (successes)": "path ratio",
    "steps without estimate": "no est.",
    "collisions": "collisions",
    "left the grid": "left grid",
    "time per step [ms]": "step [ms]",
}
#: Counts shown only where one is not zero.
MISHAPS = ("collisions", "left grid")
MISSING_NOTE = f"{MISSING_TEXT}: no value"


def narrowed(
    view: TableView,
    title: str,
    headers: dict[str, str],
    notes: Sequence[str],
    sparse: Collection[str] = (),
    grouped: bool = False,
) -> TableView:
    """``view``'s columns ``headers`` (its header -> the one shown, in that order; a header it
    lacks is skipped) with their intervals under ``title``, ``notes`` under them and a note
    on ``--`` where a cell shows one. Left out: a numeric column without a value, and a column
    of ``sparse`` (shown headers) without a non-zero value. ``grouped``: style headings over
    the rows."""
    frame = view.frame
    kept = {}
    for source, shown in headers.items():
        if source not in frame.columns:
            continue
        if source in view.digits:
            values = frame[source].astype(float)
            if values.isna().all() or (shown in sparse and not values.fillna(0).any()):
                continue
        kept[source] = shown
    bounds = {kept[c]: ends for c, ends in view.bounds.items() if c in kept}
    ends = [end for pair in bounds.values() for end in pair]
    out = frame[[*kept, *ends]].rename(columns=kept)
    digits = {kept[c]: view.digits[c] for c in kept if c in view.digits}
    digits |= {end: view.digits[end] for end in ends}
    shown = replace(
        view, title=title, frame=out, digits=digits, bounds=bounds, marked=frozenset(),
        mark_note="", notes=tuple(notes), grouped=grouped,
    )  # fmt: skip
    if (shown.text_frame() == MISSING_TEXT).to_numpy().any():
        shown = replace(shown, notes=(*shown.notes, MISSING_NOTE))
    return shown


def route_console(jobs: pd.DataFrame, labels: Sequence[str], radius_m: float) -> str:
    """The summary of a route run's per-job table ``jobs`` (routes.csv) for the console: per
    method of ``labels`` and for odometry, trials, success (within ``radius_m`` of home) and
    mean final error with their intervals, median error, path ratio, and the catchment of the
    methods probed along their route."""
    view = method_view(jobs, labels, radius_m)
    if "catchment_m" in jobs.columns:
        reach = pd.to_numeric(jobs["catchment_m"], errors="coerce").groupby(jobs["method"]).mean()
        means = view.frame["method"].map(reach).astype(float)
        frame = view.frame.assign(**{CATCHMENT: [FIXED2.round(v) for v in means]})
        view = replace(view, frame=frame, digits={**view.digits, CATCHMENT: FIXED2})
    title = (
        f"Route homing per method: success (final position within {100 * radius_m:g} cm of "
        "home) and final error [95 % interval over trials]"
    )
    notes = (
        f"path/route: the homing path over the route's length; {ODOMETRY}: dead reckoning from "
        "the same end poses; every column per trial: tables/routes.csv",
    )
    return to_text(narrowed(view, title, ROUTE_COLUMNS, notes))


def closed_loop_console(summary: pd.DataFrame) -> str:
    """The summary of a closed-loop run's summary.csv ``summary`` for the console: per style
    and method, success rate with its interval, catchment, median final distance, path ratio,
    share of steps without an estimate, collisions and exits where any, time per step."""
    notes = (
        "interval: bootstrap over starts (over goals when there are several); final: median "
        "distance from the goal at the end; path ratio: of the successes; no est.: share of "
        "steps without an estimate; every column: tables/summary.csv",
    )
    title = "Closed-loop homing per method: success rate [95 % interval]"
    view = narrowed(summary_view(summary), title, CLOSED_LOOP_COLUMNS, notes, MISHAPS, True)
    return to_text(view)


def experiment_console(kind: str, table: pd.DataFrame, config: Any) -> str:
    """The console summary of a robot run of ``kind`` ("route" or "closed-loop"): ``table``
    is the run's routes.csv or summary.csv, ``config`` its validated config."""
    if kind == "route":
        labels = [label for label, _, _ in config.method_points()]
        return route_console(table, labels, config.success_radius_m)
    return closed_loop_console(table)
