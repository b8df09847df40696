"""What the images of a run hold, as short strings for job and feature keys.

A generated set's spec key already determines every byte of its images. A real set's image is
named by its file's sha256 (what is there, whatever the manifest lists: a copy that differs
from its manifest gets its own keys, and :mod:`homebench.evaluation.data_checks` says so),
computed once and kept in ``<data dir>/cache/sha256.json`` by (path, size, mtime_ns). A view
unfolded on the fly from a raw image adds the unfolding geometry.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterable
from pathlib import Path

from homebench.data.generate import data_dir
from homebench.evaluation.sources import Source, open_source
from homebench.fileio import sha256_file, write_text_atomic
from homebench.hashing import stable_hash
from homebench.views import ImageKind

Position = tuple[int, int]


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


def image_hashes(
    source: Source, kind: ImageKind, positions: Iterable[Position]
) -> dict[Position, str]:
    """The content of the ``kind`` view at each position, as a method reads it."""
    database = open_source(source)
    positions = list(positions)
    read = kind if kind in database.kinds else "raw"
    unfold = ""
    if read != kind and source.unfold_geometry is not None:
        unfold = f" unfold {stable_hash(dataclasses.asdict(source.unfold_geometry))}"
    generator = database.manifest.generator
    if generator is not None:
        return {p: f"spec {generator.spec.key()}{unfold}" for p in positions}
    paths = {p: database.path(*p, read) for p in positions}
    hashed = file_hashes(paths.values())
    return {p: f"sha256 {hashed[path]}{unfold}" for p, path in paths.items()}
