"""What the report's numbers mean: the metrics and the statistics, as the report's definitions
page (PDF) and section (HTML, Markdown) state them.

The text restates the docstrings of :mod:`homebench.analysis.metrics`,
:mod:`~homebench.analysis.return_ratio`, :mod:`~homebench.analysis.statistics` and
:mod:`~homebench.analysis.comparisons`; the run's own settings (bins, RR step, radius) are on
the title page.
"""

from __future__ import annotations

from homebench.analysis.statistics import (
    EXACT_SIGN_FLIP_GOALS,
    LEVEL,
    N_BOOT,
    N_SIGN_FLIPS,
)

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
        "once). All robots repeat: succeed when within the success radius of the goal; fail "
        "after travelling more than the maximum travel (default: half the grid's perimeter); "
        "otherwise step a fixed length along the home direction estimated at the grid position "
        "nearest to the robot. A robot outside the grid is steered by the nearest position on "
        "the grid; a robot whose nearest position has no estimate fails. Lengths are in grid "
        "units.",
        "RR of a goal = share of the starts that reach the goal, the share of start positions "
        "from which following the home vectors leads home. A method's RR is the mean over the "
        "goals whose field covers the grid; a goal with a pair missing has no RR (n/a).",
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


def definitions(catchment: bool) -> dict[str, list[str]]:
    """The definitions of a grid run's report: heading -> paragraphs (metrics, the catchment
    when the run computed it, then the statistics)."""
    return {**METRICS, **(CATCHMENT if catchment else {}), **STATISTICS}
