"""A run config's ``claims:``: what the user expects of the methods, stated before the results.

Each claim names two methods of the run by label (``better`` expected better than ``than``; a
method's name serves where one entry runs it: :func:`with_labels`), a
``metric``, a ``condition``, optionally a distance ``band`` [lo, hi] in metres (pairs whose
current position lies that far from the goal) and a ``margin`` (in the metric's unit: degrees
for ``ae`` and ``rotation_error``, AHC for ``ahc`` and ``ahc90``, a share of starts for ``rr``)
by which ``better`` must beat ``than``. ``homebench findings`` tests them beside the papers'
findings (:mod:`homebench.analysis.user_claims`).

Robot runs (``kind: route``, ``kind: closed-loop``) take the same claims with the robot
metrics (:data:`ROBOT_METRICS`): ``success`` (the share of trials that end within the run's
success radius of home; margin: a share) and ``final_error`` (the final distance to home,
metres; lower is better; margin: metres). Their labels include the pseudo-methods the run
drives beside its methods (a route run's ``odometry`` baseline, a closed-loop run's controls
``truth`` and ``random``); their ``condition`` is optional: a route's name (route runs) or a
world style (closed-loop runs), all of the run's trials without one; they take no ``band``.
Grid claims name a condition always and no robot metric; robot claims no grid metric.

The run records each claim in ``config.resolved.json`` with when it was first ``stated`` and
how many job results the folder held then (``results_before``: 0 = stated before any result;
:mod:`homebench.evaluation.claims_record`): a claim added after the results reads as such.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from datetime import datetime
from typing import Literal

from pydantic import Field, model_validator

from homebench.strict import StrictModel
from homebench.suggest import did_you_mean

#: The metrics a claim may name: mean AE (degrees; a pair without an estimate counts as the
#: run's AHC counts it, ``metrics.ahc.missing``), the run's AHC, the AHC with a missing
#: estimate as 90 deg, the return ratio, the mean rotation error (degrees).
#: For robot runs: the share of trials ending within the success radius of home, the final
#: distance to home (metres).
ClaimMetric = Literal["ae", "ahc", "ahc90", "rr", "rotation_error", "success", "final_error"]
#: The metrics of grid runs' claims and of robot runs' (route, closed-loop).
GRID_METRICS = ("ae", "ahc", "ahc90", "rr", "rotation_error")
ROBOT_METRICS = ("success", "final_error")
#: Metrics for which lower is better.
LOWER_IS_BETTER = ("ae", "rotation_error", "final_error")


class ClaimEntry(StrictModel):
    """One claim as the user writes it (see the module docstring)."""

    better: str  # the method label expected to be better
    than: str  # the method label (or a robot run's odometry, truth, random) it is compared to
    # ae, rotation_error, ahc, ahc90, rr (grid runs); success, final_error (robot runs)
    metric: ClaimMetric
    # a grid run's condition (required); a route's name or a world style (robot runs)
    condition: str | None = None
    # [lo, hi] metres from the goal: pairs whose current lies that far (grid runs; not rr)
    band: tuple[float, float] | None = None
    margin: float = Field(0.0, ge=0)  # by how much better must beat than, in the metric's unit

    @model_validator(mode="after")
    def _consistent(self) -> ClaimEntry:
        if self.better == self.than:
            raise ValueError(f"better and than name the same method {self.better!r}")
        if self.band is not None:
            lo, hi = self.band
            if not 0 <= lo < hi:
                raise ValueError(f"band: give [lo, hi] metres with 0 <= lo < hi, got {[lo, hi]}")
            if self.metric == "rr":
                raise ValueError("band: the return ratio walks from every start; no band")
            if self.metric in ROBOT_METRICS:
                raise ValueError(f"band: a {self.metric} claim of a robot run takes no band")
        if not math.isfinite(self.margin):
            raise ValueError("margin must be finite")
        return self

    def content(self) -> dict[str, object]:
        """What the claim says (without when it was stated), as JSON values."""
        return self.model_dump(mode="json", include=set(ClaimEntry.model_fields))


class RecordedClaim(ClaimEntry):
    """A claim as the run recorded it: ``stated`` (UTC) the first time a run of the folder
    held it, ``results_before`` the job results the folder held then. None: not recorded by
    ``homebench run`` (a config edited by hand)."""

    stated: datetime | None = None
    results_before: int | None = Field(None, ge=0)


def _label_of(value: str, labels: Sequence[str], names: Mapping[str, str]) -> list[str]:
    """The labels ``value`` names: itself when a label, else the labels whose entries run the
    method of that name (``names``: label -> method name)."""
    if value in labels:
        return [value]
    return [label for label, name in names.items() if name == value]


def with_labels(claim: ClaimEntry, names: Mapping[str, str]) -> ClaimEntry:
    """``claim`` with a ``better`` or ``than`` that names a method (``names``: label ->
    method name of the run's entries) replaced by the one label that runs it (unchanged
    where it is a label already or names no single entry)."""
    changes = {}
    for key in ("better", "than"):
        value = getattr(claim, key)
        found = _label_of(value, [], names) if value not in names else [value]
        if len(found) == 1 and found[0] != value:
            changes[key] = found[0]
    return claim.model_copy(update=changes) if changes else claim


def claim_problem(
    claims: Sequence[ClaimEntry],
    labels: Sequence[str],
    conditions: Sequence[str],
    kind: str = "grid",
    names: Mapping[str, str] | None = None,
) -> str:
    """The first claim naming a method the run does not have (by label, or by method name
    when one entry runs it: ``names``, label -> method name), or a condition it does not
    have, or a metric not of runs of ``kind`` ("grid", "route" or "closed-loop"), or a grid
    claim without a condition, as "claims.0.better: ..." ("" when every claim fits)."""
    metrics = GRID_METRICS if kind == "grid" else ROBOT_METRICS
    names = names or {}
    for k, claim in enumerate(claims):
        if claim.metric not in metrics:
            other = "robot (route, closed-loop)" if kind == "grid" else "grid"
            return (
                f"claims.{k}.metric: {claim.metric!r} is a metric of {other} runs; {kind} "
                f"runs' claims take {', '.join(metrics)}"
            )
        chosen = []
        for key in ("better", "than"):
            value = getattr(claim, key)
            found = _label_of(value, labels, names)
            if not found:
                hint = did_you_mean(value, labels) or f" (labels: {', '.join(labels)})"
                return f"claims.{k}.{key}: no method labelled {value!r}{hint}"
            if len(found) > 1:
                return (
                    f"claims.{k}.{key}: {len(found)} method entries run {value} "
                    f"({', '.join(found)}); give one label"
                )
            chosen.append(found[0])
        if chosen[0] == chosen[1]:
            return f"claims.{k}: better and than name the same method entry {chosen[0]!r}"
        if claim.condition is None:
            if kind == "grid":
                return f"claims.{k}.condition: give the condition ({', '.join(conditions)})"
            continue
        if claim.condition not in conditions:
            hint = did_you_mean(claim.condition, conditions) or (
                f" (conditions: {', '.join(conditions)})"
            )
            return f"claims.{k}.condition: {claim.condition!r} is not a condition{hint}"
    return ""


def claim_text(claim: ClaimEntry) -> str:
    """The claim in words: "P beats W in ae under original-original (0-1.2 m, by 0.05)"; a
    robot claim without a condition "... in success over all trials"."""
    extras = []
    if claim.band is not None:
        extras.append(f"{claim.band[0]:g}-{claim.band[1]:g} m")
    if claim.margin:
        extras.append(f"by more than {claim.margin:g}")
    tail = f" ({', '.join(extras)})" if extras else ""
    where = "over all trials" if claim.condition is None else f"under {claim.condition}"
    return f"{claim.better} beats {claim.than} in {claim.metric} {where}{tail}"


def stated_text(claim: ClaimEntry) -> str:
    """When a claim was stated: "2026-12-07 17:40 UTC, before any result", "... after 12
    results", or "not recorded by a run"."""
    if not isinstance(claim, RecordedClaim) or claim.stated is None:
        return "not recorded by a run"
    when = claim.stated.strftime("%Y-%m-%d %H:%M UTC")
    n = claim.results_before
    after = "before any result" if n == 0 else f"after {n} job result(s)"
    return f"{when}, {after}" if n is not None else when
