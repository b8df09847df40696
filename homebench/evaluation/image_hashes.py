"""What the images of a run hold, as short strings for job and feature keys.

A generated set's spec key already determines every byte of its images. A real set's image is
named by its file's sha256 (what is there, whatever the manifest lists: a copy that differs
from its manifest gets its own keys, and :mod:`homebench.evaluation.data_checks` says so),
computed once and kept by (path, size, mtime_ns) (:mod:`homebench.data.file_hashes`). A view
unfolded on the fly from a raw image adds the unfolding geometry.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

from homebench.data.file_hashes import file_hashes
from homebench.evaluation.sources import Source, open_source
from homebench.hashing import stable_hash
from homebench.views import ImageKind

Position = tuple[int, int]


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
