"""Which images a cell of a run's tables was measured on, so that cells of several runs are
pooled, paired or ranked together only when they hold the same pairs.

A pair's databases are named by their keys (``current_database_key`` and
``goal_database_key`` in the pair table; see :class:`~homebench.evaluation.sources.Source`: a
manifest's name and the key of its images' content, or a generated world's spec key). A
cell's **world key** is the sorted set of its pairs' (current, goal) database keys: one pair
of databases for a plain condition, several for a seed sweep. The quick start's 5 x 7
"original-original" and a 10 x 17 set's have other keys, however alike their names.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import pandas as pd

#: A long hex digest at the end of a database key, shortened in labels.
_DIGEST = re.compile(r"-([0-9a-f]{8})[0-9a-f]+$")


def world_keys(pairs: pd.DataFrame, by: Sequence[str]) -> dict[tuple[object, ...], str]:
    """The world key of each group of ``pairs`` by the columns ``by`` (a missing value, as
    the style of a run that sweeps none, as ""); "" for a table without database keys."""
    if pairs.empty:
        return {}
    if "current_database_key" not in pairs.columns:
        return {key: "" for key in _keys(pairs, by)}
    found = {}
    for key, rows in pairs.groupby(list(by), sort=False, dropna=False):
        keys = zip(rows["current_database_key"], rows["goal_database_key"], strict=True)
        found[_clean(key)] = "; ".join(sorted({f"{c} > {g}" for c, g in keys}))
    return found


def _keys(pairs: pd.DataFrame, by: Sequence[str]) -> list[tuple[object, ...]]:
    return [_clean(key) for key, _ in pairs.groupby(list(by), sort=False, dropna=False)]


def _clean(key: object) -> tuple[object, ...]:
    parts = key if isinstance(key, tuple) else (key,)
    return tuple("" if pd.isna(part) else part for part in parts)


def world_label(key: str) -> str:
    """A short name of a world key: a database's key (its digest cut to 8 hex digits), or
    "current / goal" for two, or the first and the count of the rest for a sweep."""
    pairs = [part.split(" > ") for part in key.split("; ")] if key else []
    if not pairs:
        return "?"
    current, goal = (_DIGEST.sub(r"-\1", name) for name in pairs[0])
    first = current if current == goal else f"{current} / {goal}"
    return first if len(pairs) == 1 else f"{first} and {len(pairs) - 1} more"
