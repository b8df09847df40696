"""What ``homebench data generate`` says it made: the world, its grid, its images, where, and
how long it took (or that the set was already there)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from homebench.data.database import GridDatabase
from homebench.data.generate import Progress


@dataclass(frozen=True)
class Made:
    """A generated ``database``, the ``seconds`` its generation call took, and whether it
    ``rendered`` anything (False: the folder held the set already)."""

    database: GridDatabase
    seconds: float
    rendered: bool


def timed(generate: Callable[[Progress], GridDatabase]) -> Made:
    """Call ``generate(progress)`` (a generation taking a progress callback) and time it."""
    rendered = False

    def progress(done: int, total: int) -> None:
        nonlocal rendered
        rendered = True

    started = time.perf_counter()
    database = generate(progress)
    return Made(database, time.perf_counter() - started, rendered)


def made_line(made: Made, where: Path | None = None) -> str:
    """One line: ``name: generated in 61.2 s: world posters, variant original, seed 0; grid
    10 x 17, 0.30 m apart; 340 images (raw 420 x 420, unfolded 360 x 95) in DIR``; ``where``:
    the folder written, when not the database's own (a Brains on Board copy)."""
    manifest = made.database.manifest
    done = f"generated in {made.seconds:.1f} s" if made.rendered else "already generated"
    parts = [f"{manifest.name}: {done}"]
    if manifest.generator is not None:
        spec = manifest.generator.spec
        parts.append(f"world {spec.style}, variant {spec.variant}, seed {spec.seed}")
    nx, ny = manifest.grid.shape
    sizes = [f"{kind} {' x '.join(map(str, manifest.section(kind).size))}" for kind in
             manifest.kinds]  # fmt: skip
    images = nx * ny * len(manifest.kinds)
    grid = f"grid {nx} x {ny}, {manifest.grid.spacing:.2f} m apart"
    folder = made.database.root if where is None else where
    return f"{': '.join(parts)}; {grid}; {images} images ({', '.join(sizes)}) in {folder}"
