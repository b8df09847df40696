"""What the report's numbers mean: the metrics and the statistics, as the report's definitions
page (PDF) and section (HTML, Markdown) state them.

The text restates the docstrings of :mod:`homebench.analysis.metrics`,
:mod:`~homebench.analysis.return_ratio`, :mod:`~homebench.analysis.statistics`,
:mod:`~homebench.analysis.comparisons` and :mod:`~homebench.analysis.tables` (bands, flips);
the run's AHC definition, RR settings and distance bands are stated here, its other settings
(bins) on the title page.
"""

from __future__ import annotations

from homebench.analysis.statistics import (
    EXACT_SIGN_FLIP_GOALS,
    LEVEL,
    N_BOOT,
    N_SIGN_FLIPS,
)
from homebench.analysis.tables import FLIP_DEG
from homebench.config import MetricsConfig
from homebench.report.tables import AHC_MEANINGS, ahc_header, rr_reading

METRICS = {
    "AE, angular error (seed 001, eq. 11)": [
        "AE = |wrap(estimate - true home direction)|, in [0, 180] deg, per pair of a current and "
        "a goal position; the true home direction is atan2(yH - yC, xH - xC) in the world frame. "
        "A pair for which the method gave no estimate has no AE: it is counted (the share "
        "without an estimate) and never dropped silently. Mean and median AE are over the pairs "
        "with an estimate.",
    ],
    "AHC, average homeward component (eq. 12)": [
        "AHC = cos(mean AE) over the pairs of a distance bin (or over all pairs), in [-1, 1]: 1 "
        "when every home vector points at the goal, 0 for a mean AE of 90 deg, what random "
        "guesses give. A pair belongs to the distance bin whose centre is nearest.",
        "AHC (the paper's reading) averages over the pairs with an estimate, so a method that "
        "abstains where it is unsure is not penalised. The variant 'AHC (no est. = 90 deg)' "
        "counts a missing estimate as AE = 90 deg, the expected error of a random guess; the "
        "two agree when every pair has an estimate.",
    ],
    "RR, return ratio (eq. 13, Moeller's step procedure)": [
        "A dummy robot starts at every grid position (the goal included, which succeeds at "
        "once). All robots repeat: succeed when within the success radius (grid units: "
        "multiples of the grid spacing; seed 001: 0.5) of the goal; fail after travelling "
        "more than the maximum travel (default: half the grid's perimeter); otherwise step a "
        "fixed length (seed 001: 0.8 grid units) along the home direction estimated at the "
        "grid position nearest to the robot. A robot outside the grid is steered by the "
        "nearest position on the grid. A robot whose nearest position has no estimate stops "
        "there; seed 001's procedure presumes an estimate everywhere and is silent on this, so "
        "the walk fails by default (metrics.return_ratio.no_estimate: fail), or, with "
        "'arrived', succeeds when that position is one of the goal's 8 grid neighbours (where "
        "warping-like methods abstain because the view looks like home) and fails elsewhere. "
        "The RR table gives per goal the share of walks that ended so.",
        "RR of a goal = share of the starts that reach the goal, the share of start positions "
        "from which following the home vectors leads home. A method's RR is the mean over the "
        "goals whose field covers the grid; a goal with a pair missing has no RR (n/a).",
        "A database of posed images that is no grid (a route, any poses) has no RR or "
        "catchment (n/a): the robot's steps need home directions on a grid around the goal; "
        "its pairs have AE, AHC and the distance bands as a grid's.",
    ],
}

CATCHMENT = {
    "Catchment (Moeller's discrete variant)": [
        "From each grid node the robot moves to the 8-neighbour whose direction is closest to "
        "the home direction estimated at the node. It succeeds on reaching the goal node and "
        "fails on stepping off the grid, on a node without an estimate or on revisiting a node "
        "(a cycle). Catchment = share of the grid's nodes that reach the goal.",
    ],
}

STATISTICS = {
    f"{LEVEL:.0%} intervals: goal bootstrap, expanded percentile": [
        "The goal is the unit of replication: all pairs of a goal share its image and its home "
        "vector field, and all return-ratio starts of a goal follow that one field, so they are "
        "not independent. An interval therefore resamples goals with replacement "
        f"({N_BOOT} resamples, seeded per table cell so a table is the same on every run) and "
        "recomputes the metric over the drawn goals' pairs (the cluster bootstrap).",
        "The interval is an expanded percentile interval (Hesterberg 2015): percentiles of the "
        "resampled metric at a level widened for n goals, 2 Phi(sqrt(n / (n - 1)) t_{n-1}) - 1. "
        "Percentiles respect monotone transformations (the AHC interval is cos of the mean-AE "
        "interval; rates stay in [0, 1]); the expansion corrects the plain percentile "
        "interval, which is too narrow for few goals (84 % coverage at a nominal 95 % for 5 "
        "goals; expanded: 92 %).",
        "An interval needs at least two goals (otherwise it is shown as '--'), and no bootstrap "
        "reaches beyond the range of the per-goal values: with 3 goals an interval covers about "
        "75 % whatever its level. The number of goals stands beside every interval.",
    ],
    "Paired tests (homebench compare, homebench findings)": [
        "Two methods are compared on the same pairs (matched on goal and current position) or "
        "the same return-ratio starts; differences are B - A, with a paired goal-bootstrap "
        "interval. A pair without an estimate counts as AE = 90 deg by default, or is left out "
        "and counted.",
        "Goal-level sign-flip test: under the null hypothesis the two methods are exchangeable "
        "within a goal, so the sign of each goal's total difference is flipped; exact (all 2^n "
        f"patterns) up to {EXACT_SIGN_FLIP_GOALS} goals, else {N_SIGN_FLIPS} seeded random "
        "patterns. Its smallest possible p is 2 / 2^n: 5 goals never reach p < 0.05. Findings "
        "rest on this test.",
        "Per-pair tests beside it: Wilcoxon's signed-rank test on the AE differences, McNemar's "
        "exact test on the RR start outcomes. They treat pairs as independent, which pairs of "
        "a goal are not, so their p-values are too small (anti-conservative).",
        "Holm's step-down correction adjusts the p-values of every AE and RR comparison of a "
        "table (one family); the AHC difference shares the test of its mean-AE difference.",
    ],
}


ROTATION = {
    "Rotation error and flips": [
        "Rotation error = |wrap(estimated - true heading change)| from the goal's view to the "
        "current one, over the pairs for which the method reports a rotation (a compass "
        "method reports nothing else); its mean in deg. Flips: the share of those estimates "
        f"off by more than {FLIP_DEG:g} deg, a view taken for its opposite, as a visual compass "
        "does far from the goal. A few flips weigh in a mean as much as many small errors, so "
        "the flips stand beside it.",
    ],
}


def bands_text(edges: tuple[float, ...]) -> str:
    """The distance bands of ``edges`` (m) in words: "below 1.2 m, 1.2 to 2.4 m, from 2.4 m"."""
    inner = [f"{lo:g} to {hi:g} m" for lo, hi in zip(edges, edges[1:], strict=False)]
    return ", ".join([f"below {edges[0]:g} m", *inner, f"from {edges[-1]:g} m"])


def _run_settings(metrics: MetricsConfig) -> dict[str, list[str]]:
    """The AHC definition, the RR settings and the distance bands as the run set them."""
    return {
        "AHC definitions": [
            "Two AHCs are in the literature: seed 001's eq. 12, the cosine of the mean AE "
            "(metrics.ahc.definition: cos_mean_ae, the default), and the mean of cos(AE), the "
            "mean homeward component of a unit home vector, which Vardy & Moeller (2005) and "
            "Moeller & Vardy (2006) report (mean_cos). A cosine of a mean is not a mean of "
            "cosines: set a table beside another paper's only when both use one definition. "
            f"This run's AHC is {AHC_MEANINGS[metrics.ahc.definition]} (headers say "
            f"'{ahc_header('AHC', metrics.ahc)}').",
        ],
        "Return ratio (RR) settings": [f"This run's RR: {rr_reading(metrics.return_ratio)}."],
        "Distance bands": [
            "The band table gives AHC (both readings), mean AE, the share without an estimate, "
            "rotation error and flips per band of distance between current and goal position "
            f"(metrics.band_edges_m; this run: {bands_text(metrics.band_edges_m)}), each with "
            "its goal-bootstrap interval in tables/bands.csv, so that one mean over every "
            "distance does not blend a method that homes well near the goal with one that fails "
            "far from it.",
        ],
    }


def definitions(metrics: MetricsConfig) -> dict[str, list[str]]:
    """The definitions of a grid run's report: heading -> paragraphs (metrics, the run's AHC
    definition and distance bands, rotation error, the catchment when the run computed it,
    then the statistics)."""
    catchment = CATCHMENT if metrics.catchment else {}
    return {**METRICS, **_run_settings(metrics), **ROTATION, **catchment, **STATISTICS}
