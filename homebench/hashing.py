"""Stable content hashes: the keys of caches, jobs and generated worlds."""

from __future__ import annotations

import hashlib
import json
from typing import Any


def canonical_json(value: Any) -> str:
    """JSON with sorted keys and no spaces: equal values give equal strings."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=_fallback)


def stable_hash(value: Any, length: int = 16) -> str:
    """First ``length`` hex digits of the sha256 of ``canonical_json(value)``."""
    return hashlib.sha256(canonical_json(value).encode()).hexdigest()[:length]


def derived_seed(*parts: Any) -> int:
    """A 63-bit seed derived from ``parts`` (stable across processes and platforms)."""
    return int(stable_hash(list(parts), 16), 16) >> 1


def _fallback(value: Any) -> Any:
    if isinstance(value, tuple | set | frozenset):
        return sorted(value) if isinstance(value, set | frozenset) else list(value)
    if hasattr(value, "item"):  # numpy scalars
        return value.item()
    raise TypeError(f"cannot hash a {type(value).__name__}")
