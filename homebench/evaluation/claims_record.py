"""When each claim of a run was stated: kept from the first run that recorded it.

``homebench run`` writes the config's claims into ``config.resolved.json`` before any job
runs, each with ``stated`` (UTC, ISO 8601) and ``results_before`` (the job results the folder
already held). A claim that the folder's earlier record holds keeps that record's stamp; a
new one (added with ``--update``) gets the time of this run and the results it comes after.
Robot runs (route, closed-loop) record theirs the same way before any trial runs, counting
their trial files (``results``: :data:`ROUTE_RESULTS`, :data:`CLOSED_LOOP_RESULTS`).
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from homebench.claim_spec import ClaimEntry
from homebench.fileio import parse_json, read_record_text
from homebench.hashing import stable_hash

CONFIG_FILE = "config.resolved.json"
STAMP_KEYS = ("stated", "results_before")
#: Where each kind of run keeps its results (globs under the run folder).
GRID_RESULTS = "jobs/*.json"
ROUTE_RESULTS = "routes/**/*.json"
CLOSED_LOOP_RESULTS = "trials/**/*.json"


def _identity(claim: dict[str, Any]) -> str:
    """A claim's content (what it says, not when), hashed."""
    return stable_hash({k: v for k, v in claim.items() if k not in STAMP_KEYS})


def _earlier_stamps(run_dir: Path) -> dict[str, dict[str, Any]]:
    """The stamps of the claims the folder's resolved config records, by claim identity; an
    unreadable or absent record has none."""
    try:
        previous = parse_json(read_record_text(run_dir / CONFIG_FILE))
    except (OSError, ValueError):
        return {}
    claims = previous.get("claims") if isinstance(previous, dict) else None
    stamps: dict[str, dict[str, Any]] = {}
    for claim in claims if isinstance(claims, list) else []:
        if isinstance(claim, dict) and claim.get("stated"):
            stamp = {key: claim.get(key) for key in STAMP_KEYS}
            stamps.setdefault(_identity(claim), stamp)
    return stamps


def stamped_claims(
    claims: list[ClaimEntry],
    run_dir: Path,
    now: datetime | None = None,
    results: str = GRID_RESULTS,
) -> list[dict[str, Any]]:
    """``claims`` as the resolved config records them (JSON values): each with its earlier
    stamp where ``run_dir``'s record holds it, else stated ``now`` (default: the current UTC
    time, to the second) after the results now in ``run_dir`` (the files matching
    ``results``: a grid run's job results by default)."""
    earlier = _earlier_stamps(Path(run_dir))
    when = (now or datetime.now(UTC)).isoformat(timespec="seconds")
    n_results = sum(1 for _ in Path(run_dir).glob(results)) if Path(run_dir).is_dir() else 0
    recorded = []
    for claim in claims:
        content = claim.content()
        stamp = earlier.get(_identity(content), {"stated": when, "results_before": n_results})
        recorded.append(content | stamp)
    return recorded


def with_stamped_claims(
    resolved: dict[str, Any], claims: list[ClaimEntry], run_dir: Path, results: str
) -> dict[str, Any]:
    """A robot run's resolved config (``resolved``) with its ``claims`` stamped
    (:func:`stamped_claims`, counting the files ``results`` matches); without a ``claims``
    key when there are none (as recorded before robot runs had claims)."""
    if not claims:
        return resolved
    return resolved | {"claims": stamped_claims(claims, run_dir, results=results)}
