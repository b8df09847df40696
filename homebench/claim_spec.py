"""A run config's ``claims:``: what the user expects of the methods, stated before the results.

Each claim names two method labels of the run (``better`` expected better than ``than``), a
``metric``, a ``condition``, optionally a distance ``band`` [lo, hi] in metres (pairs whose
current position lies that far from the goal) and a ``margin`` (in the metric's unit: degrees
for ``ae`` and ``rotation_error``, AHC for ``ahc`` and ``ahc90``, a share of starts for ``rr``)
by which ``better`` must beat ``than``. ``homebench findings`` tests them beside the papers'
findings (:mod:`homebench.analysis.user_claims`).

The run records each claim in ``config.resolved.json`` with when it was first ``stated`` and
how many job results the folder held then (``results_before``: 0 = stated before any result;
:mod:`homebench.evaluation.claims_record`): a claim added after the results reads as such.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from datetime import datetime
from typing import Literal

from pydantic import Field, model_validator

from homebench.strict import StrictModel
from homebench.suggest import did_you_mean

#: The metrics a claim may name: mean AE (degrees; a pair without an estimate counts as the
#: run's AHC counts it, ``metrics.ahc.missing``), the run's AHC, the AHC with a missing
#: estimate as 90 deg, the return ratio, the mean rotation error (degrees).
ClaimMetric = Literal["ae", "ahc", "ahc90", "rr", "rotation_error"]
#: Metrics for which lower is better.
LOWER_IS_BETTER = ("ae", "rotation_error")


class ClaimEntry(StrictModel):
    """One claim as the user writes it (see the module docstring)."""

    better: str
    than: str
    metric: ClaimMetric
    condition: str
    band: tuple[float, float] | None = None
    margin: float = Field(0.0, ge=0)

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


def claim_problem(
    claims: Sequence[ClaimEntry], labels: Sequence[str], conditions: Sequence[str]
) -> str:
    """The first claim naming a method label or condition the run does not have, as
    "claims.0.better: ..." ("" when every claim fits)."""
    for k, claim in enumerate(claims):
        for key in ("better", "than"):
            label = getattr(claim, key)
            if label not in labels:
                hint = did_you_mean(label, labels) or f" (labels: {', '.join(labels)})"
                return f"claims.{k}.{key}: no method labelled {label!r}{hint}"
        if claim.condition not in conditions:
            hint = did_you_mean(claim.condition, conditions) or (
                f" (conditions: {', '.join(conditions)})"
            )
            return f"claims.{k}.condition: {claim.condition!r} is not a condition{hint}"
    return ""


def claim_text(claim: ClaimEntry) -> str:
    """The claim in words: "P beats W in ae under original-original (0-1.2 m, by 0.05)"."""
    extras = []
    if claim.band is not None:
        extras.append(f"{claim.band[0]:g}-{claim.band[1]:g} m")
    if claim.margin:
        extras.append(f"by more than {claim.margin:g}")
    tail = f" ({', '.join(extras)})" if extras else ""
    return f"{claim.better} beats {claim.than} in {claim.metric} under {claim.condition}{tail}"


def stated_text(claim: ClaimEntry) -> str:
    """When a claim was stated: "2026-12-07 17:40 UTC, before any result", "... after 12
    results", or "not recorded by a run"."""
    if not isinstance(claim, RecordedClaim) or claim.stated is None:
        return "not recorded by a run"
    when = claim.stated.strftime("%Y-%m-%d %H:%M UTC")
    n = claim.results_before
    after = "before any result" if n == 0 else f"after {n} job result(s)"
    return f"{when}, {after}" if n is not None else when
