"""Time generating one full grid database (both image kinds) with 1 and with 2 jobs.

Usage: python benchmarks/bench_generate.py [--grid NX NY]

Prints the data layer's own cost per image (PNG encoding, sha256, atomic write), then the total
and per-image time of a full generation with jobs=1 (the reference) and jobs=2, and whether both
wrote identical bytes. Everything goes to a temporary folder that is removed afterwards.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from homebench.data.generate import generate
from homebench.data.synth.spec import GridSpec, WorldSpec
from homebench.fileio import encode_png, write_bytes_atomic


def io_cost(spec: WorldSpec, folder: Path, repeats: int = 20) -> dict[str, float]:
    """Seconds per image to encode, hash and atomically write a noisy image of each kind."""
    rng = np.random.default_rng(0)
    shapes = {
        "raw": (spec.raw.height, spec.raw.width),
        "unfolded": (spec.unfolded.height, spec.unfolded.width),
    }
    cost = {}
    for kind, shape in shapes.items():
        image = np.clip(rng.normal(128, 40, shape), 0, 255).astype(np.uint8)
        start = time.perf_counter()
        for k in range(repeats):
            data = encode_png(image)
            hashlib.sha256(data).hexdigest()
            write_bytes_atomic(folder / f"{kind}-{k}.png", data)
        cost[kind] = (time.perf_counter() - start) / repeats
    return cost


def timed_generation(spec: WorldSpec, out: Path, jobs: int) -> float:
    start = time.perf_counter()
    generate(spec, out, jobs, "bench")
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", nargs=2, type=int, default=(10, 17), metavar=("NX", "NY"))
    args = parser.parse_args()
    spec = WorldSpec(grid=GridSpec(shape=tuple(args.grid)))
    n_images = 2 * spec.to_grid().size
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for kind, seconds in io_cost(spec, folder).items():
            print(f"I/O per {kind} image (encode + sha256 + atomic write): {seconds * 1e3:.1f} ms")
        if importlib.util.find_spec("homebench.data.synth.world") is None:
            print("no renderer (homebench.data.synth.world) yet: generation not timed")
            return 1
        times = {jobs: timed_generation(spec, folder / f"jobs{jobs}", jobs) for jobs in (1, 2)}
        for jobs, seconds in times.items():
            print(
                f"jobs={jobs}: {seconds:.1f} s for {args.grid[0]} x {args.grid[1]} positions, "
                f"{n_images} images ({seconds / n_images * 1e3:.0f} ms per image)"
            )
        same = all(
            p.read_bytes() == (folder / "jobs2" / p.relative_to(folder / "jobs1")).read_bytes()
            for p in (folder / "jobs1").rglob("*")
            if p.is_file()
        )
        print(f"speed-up with 2 jobs: {times[1] / times[2]:.2f}x; identical bytes: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
