"""Route runs with several methods: per-method statistics, paired tests, their figures.

Every method of a route run homes on the same trials (the same outbound drive and noise), and
the odometry baseline is one more "method" on them. **The trial is the unit of replication**:
trials have their own motion noise and are independent, so intervals resample trials
(:class:`~homebench.analysis.statistics.GoalResampler` with one cluster per trial, the
expanded percentile interval) and the paired tests take one difference per trial: the
sign-flip test over trials (exact up to 16 trials), Wilcoxon's signed rank test and McNemar's
exact test on success, all on the trials both methods finished; Holm's adjustment runs over
the sign-flip p-values of the table.

Input: the per-job table (one row per trial and method, the columns of a trial's ``summary``
plus ``method`` and ``success``), in the run's plan order.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from homebench.analysis.statistics import (
    GoalResampler,
    holm,
    mcnemar_exact,
    mean_interval,
    sign_flip_test,
    wilcoxon_test,
)
from homebench.experiments.route.config import ODOMETRY
from homebench.report.route.figures import ERROR_FLOOR_M
from homebench.report.style import (
    DOUBLE_COLUMN,
    FAILED_COLOUR,
    MethodStyle,
    legend_right,
    new_figure,
)
from homebench.report.tables import FIXED0, FIXED1, FIXED2, P_VALUE, TableView, make_view

ERROR_FIGURE_HEIGHT = 3.6


def long_errors(jobs: pd.DataFrame, radius_m: float) -> pd.DataFrame:
    """One row per (trial, method) with the odometry baseline as a method of its own: columns
    trial, route, length_m, driven_m, method, error_cm, success (within ``radius_m`` metres
    of home), path_ratio, legs, steps (NaN where the baseline has none). ``jobs``: the
    per-job table."""
    frame = jobs.assign(
        error_cm=100.0 * jobs["visual_error_m"].astype(float),
        path_ratio=jobs["visual_path_m"].astype(float) / jobs["driven_m"].astype(float),
        steps=jobs["visual_steps"].astype(float),
        legs=jobs["legs"].astype(float),
    )
    columns = ["trial", "route", "length_m", "driven_m", "method", "error_cm", "success"]
    odometry = jobs.drop_duplicates("trial").assign(
        method=ODOMETRY, error_cm=100.0 * jobs["odometry_error_m"].astype(float)
    )
    more = ["path_ratio", "legs", "steps"]
    both = pd.concat([frame[columns[:-1] + more], odometry[columns[:-1]]], ignore_index=True)
    both["success"] = both["error_cm"] <= 100.0 * radius_m
    return both


def _trial_codes(trials: pd.Series) -> np.ndarray:
    """Trial names as integer cluster labels (the same name, the same code)."""
    return pd.factorize(trials, sort=True)[0]


def method_view(jobs: pd.DataFrame, labels: Sequence[str], radius_m: float) -> TableView:
    """Per method (config order, odometry last): trials, success rate and mean final error
    with their intervals over trials, median error, path ratio, legs and steps."""
    frame = long_errors(jobs, radius_m)
    rows = []
    for label in [*labels, ODOMETRY]:
        mine = frame[frame["method"] == label]
        if mine.empty:
            continue
        resampler = GoalResampler(_trial_codes(mine["trial"]))
        error = mean_interval(mine["error_cm"], resampler)
        success = mean_interval(mine["success"].astype(float), resampler)
        rows.append(
            {
                "method": label,
                "trials": len(mine),
                "success [%]": 100 * success.estimate,
                "s_lo": 100 * success.lo,
                "s_hi": 100 * success.hi,
                "final error mean [cm]": error.estimate,
                "e_lo": error.lo,
                "e_hi": error.hi,
                "final error median [cm]": float(mine["error_cm"].median()),
                "path / route length": float(mine["path_ratio"].mean()),
                "legs": float(mine["legs"].mean()),
                "steps": float(mine["steps"].mean()),
            }
        )
    shown = pd.DataFrame(rows)
    digits = {
        "trials": FIXED0,
        "success [%]": FIXED0,
        "final error mean [cm]": FIXED2,
        "final error median [cm]": FIXED2,
        "path / route length": FIXED2,
        "legs": FIXED1,
        "steps": FIXED0,
    }
    bounds = {"success [%]": ("s_lo", "s_hi"), "final error mean [cm]": ("e_lo", "e_hi")}
    title = (
        f"Route homing per method on the same trials: success (final position within "
        f"{100 * radius_m:g} cm of home) and final error, 95 % intervals over trials"
    )
    notes = ("path / route length: the homing path over the outbound route's length",)
    return make_view("routes_by_method", title, shown, digits, bounds, notes=notes)


def length_view(jobs: pd.DataFrame, labels: Sequence[str], radius_m: float) -> TableView:
    """Per method, route and planned length: trials, success, mean final error (interval)."""
    frame = long_errors(jobs, radius_m)
    rows = []
    for label in [*labels, ODOMETRY]:
        mine = frame[frame["method"] == label]
        for (route, length), group in mine.groupby(["route", "length_m"], sort=False):
            error = mean_interval(group["error_cm"], GoalResampler(_trial_codes(group["trial"])))
            rows.append(
                {
                    "method": label,
                    "route": route,
                    "length [m]": length,
                    "trials": len(group),
                    "success": int(group["success"].sum()),
                    "final error mean [cm]": error.estimate,
                    "lo": error.lo,
                    "hi": error.hi,
                }
            )
    digits = {"length [m]": FIXED2, "trials": FIXED0, "success": FIXED0}
    digits["final error mean [cm]"] = FIXED2
    title = "Route homing per method and route length: final error, 95 % intervals over trials"
    bounds = {"final error mean [cm]": ("lo", "hi")}
    return make_view("routes_by_method_length", title, pd.DataFrame(rows), digits, bounds)


def paired_view(jobs: pd.DataFrame, labels: Sequence[str], radius_m: float) -> TableView:
    """Every pair of methods (odometry included, as A) on the trials both finished: the
    mean difference of final error B - A with its interval, the p-values, the successes of
    one alone."""
    frame = long_errors(jobs, radius_m)
    wide_error = frame.pivot(index="trial", columns="method", values="error_cm")
    wide_success = frame.pivot(index="trial", columns="method", values="success")
    rows = []
    for a, b in itertools.combinations([ODOMETRY, *labels], 2):
        both = wide_error[[a, b]].dropna().index
        if both.empty:
            continue
        difference = (wide_error.loc[both, b] - wide_error.loc[both, a]).to_numpy(float)
        codes = _trial_codes(pd.Series(both))
        interval = mean_interval(difference, GoalResampler(codes))
        success = mcnemar_exact(
            wide_success.loc[both, a].astype(bool), wide_success.loc[both, b].astype(bool)
        )
        rows.append(
            {
                "A": a,
                "B": b,
                "trials": len(both),
                "B - A final error [cm]": interval.estimate,
                "lo": interval.lo,
                "hi": interval.hi,
                "p sign-flip": sign_flip_test(difference),
                "p Holm": np.nan,
                "p Wilcoxon": wilcoxon_test(difference),
                "success A only": success.only_a,
                "success B only": success.only_b,
                "p McNemar": success.p_value,
            }
        )
    shown = pd.DataFrame(rows)
    if not shown.empty:
        shown["p Holm"] = holm(shown["p sign-flip"].to_numpy(float))
    digits = {
        "trials": FIXED0,
        "B - A final error [cm]": FIXED2,
        "p sign-flip": P_VALUE,
        "p Holm": P_VALUE,
        "p Wilcoxon": P_VALUE,
        "success A only": FIXED0,
        "success B only": FIXED0,
        "p McNemar": P_VALUE,
    }
    title = "Route homing, paired comparisons on the same trials (negative: B ends nearer home)"
    notes = (
        "p sign-flip: over trials (the unit of replication), Holm-adjusted over the table; "
        "Wilcoxon: signed ranks of the differences; McNemar: exact, on success",
    )
    bounds = {"B - A final error [cm]": ("lo", "hi")}
    return make_view("routes_paired", title, shown, digits, bounds, notes=notes)


def error_interval_figure(jobs: pd.DataFrame, styles: dict[str, MethodStyle]) -> Figure:
    """Final position error against route length per method and for odometry: the mean over
    the trials of each planned length (at their mean driven length) with its 95 % interval
    over trials as error bars. Log error axis (errors below ERROR_FLOOR_M drawn at it)."""
    frame = long_errors(jobs, 0.0)  # success plays no part here
    fig = new_figure((DOUBLE_COLUMN, ERROR_FIGURE_HEIGHT))
    ax = fig.add_subplot()
    floor = 100.0 * ERROR_FLOOR_M
    drawn = {**styles, ODOMETRY: MethodStyle(FAILED_COLOUR, "x", "--")}
    lengths = sorted(frame["length_m"].unique())
    offsets = np.linspace(-0.12, 0.12, len(drawn)) if len(drawn) > 1 else np.zeros(1)
    for offset, (label, style) in zip(offsets, drawn.items(), strict=True):
        mine = frame[frame["method"] == label]
        points = []
        for length in lengths:
            group = mine[mine["length_m"] == length]
            if group.empty:
                continue
            error = mean_interval(group["error_cm"], GoalResampler(_trial_codes(group["trial"])))
            x = float(group["driven_m"].astype(float).mean()) + offset
            points.append((x, error.estimate, error.lo, error.hi))
        if not points:
            continue
        x, mean, lo, hi = (np.array(v, dtype=float) for v in zip(*points, strict=True))
        mean = np.maximum(mean, floor)
        below = np.where(np.isfinite(lo), mean - np.maximum(lo, floor), 0.0)
        above = np.where(np.isfinite(hi), np.maximum(hi, floor) - mean, 0.0)
        ax.errorbar(x, mean, yerr=[np.maximum(below, 0), np.maximum(above, 0)],
                    color=style.colour, marker=style.marker, linestyle=style.linestyle,
                    markersize=5, capsize=2, label=label)  # fmt: skip
    ax.set_yscale("log")
    ax.set_xlim(left=0.0)
    ax.set_xlabel("route length [m] (mean driven length of each planned length)")
    ax.set_ylabel(f"final position error [cm] (log; below {floor:g} cm drawn at it)")
    ax.grid(True, which="both", alpha=0.3)
    legend_right(ax, "mean over trials\n(bars: 95 % interval)")
    return fig
