"""The sha256 of image files, computed once and kept in ``<data dir>/cache/sha256.json`` by
(path, size, mtime_ns): a real set's images are hashed on its first run, then only looked up."""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

from homebench.data.generate import data_dir
from homebench.fileio import sha256_file, write_text_atomic


def _cache_path() -> Path:
    return data_dir() / "cache" / "sha256.json"


def file_hashes(paths: Iterable[Path]) -> dict[Path, str]:
    """sha256 of each file, read from the cache when its size and mtime are unchanged."""
    cache_path = _cache_path()
    try:
        cache = json.loads(cache_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        cache = {}
    cache = cache if isinstance(cache, dict) else {}
    found, changed = {}, False
    for path in paths:
        resolved = path.resolve()
        stat = resolved.stat()
        entry = cache.get(str(resolved))
        if not (isinstance(entry, list) and entry[:2] == [stat.st_size, stat.st_mtime_ns]):
            entry, changed = [stat.st_size, stat.st_mtime_ns, sha256_file(resolved)], True
            cache[str(resolved)] = entry
        found[path] = str(entry[2])
    if changed:
        cache_path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(cache_path, json.dumps(cache))
    return found
