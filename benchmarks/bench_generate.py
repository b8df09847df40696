"""Time generating one full grid database (both image kinds) with 1 and with 2 jobs.

Usage: python benchmarks/bench_generate.py [--grid NX NY]

Prints, per grid position (one raw and one unfolded image), process CPU and wall time of the
data layer's own cost (PNG encoding, sha256, atomic write) and of a full generation with
jobs=1 (the reference) and jobs=2 (CPU of this process and its workers), each CPU time over a
floor measured in the same process: the bare ``cv2.imencode`` of the position's two images with
homebench's PNG settings. Then the speed-up with 2 jobs, whether both wrote identical bytes,
and the load average before and after. Everything goes to a temporary folder that is removed
afterwards.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from joblib.externals.loky import get_reusable_executor
from timing import cpu_and_wall, cpu_with_children, load, print_figures

from homebench.data.generate import generate
from homebench.data.synth.spec import GridSpec, WorldSpec
from homebench.fileio import PNG_PARAMS, encode_png, write_bytes_atomic


def _noisy_images(spec: WorldSpec) -> list[np.ndarray]:
    """A noisy raw and a noisy unfolded image of the spec's sizes (uint8)."""
    rng = np.random.default_rng(0)
    shapes = [(spec.raw.height, spec.raw.width), (spec.unfolded.height, spec.unfolded.width)]
    return [np.clip(rng.normal(128, 40, shape), 0, 255).astype(np.uint8) for shape in shapes]


def timed_generation(spec: WorldSpec, out: Path, jobs: int) -> tuple[float, float]:
    """CPU seconds (this process and its workers) and wall seconds of one generation."""
    cpu, wall = cpu_with_children(), time.perf_counter()
    generate(spec, out, jobs, "bench")
    wall = time.perf_counter() - wall
    get_reusable_executor().shutdown(wait=True)  # joblib's workers end, so their CPU counts
    return cpu_with_children() - cpu, wall


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", nargs=2, type=int, default=(10, 17), metavar=("NX", "NY"))
    args = parser.parse_args()
    print(load())
    spec = WorldSpec(grid=GridSpec(shape=tuple(args.grid)))
    positions = spec.to_grid().size
    images = _noisy_images(spec)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)

        def write_both() -> None:
            for kind, image in zip(("raw", "unfolded"), images, strict=True):
                data = encode_png(image)
                hashlib.sha256(data).hexdigest()
                write_bytes_atomic(folder / f"{kind}.png", data)

        floor = "floor: bare cv2.imencode PNG, raw + unfolded"
        figures = {
            floor: cpu_and_wall(
                lambda: [cv2.imencode(".png", image, list(PNG_PARAMS)) for image in images], 10
            ),
            "I/O: encode + sha256 + atomic write": cpu_and_wall(write_both, 10),
        }
        for jobs in (1, 2):
            cpu, wall = timed_generation(spec, folder / f"jobs{jobs}", jobs)
            figures[f"generation, jobs={jobs}"] = (cpu / positions, wall / positions)
        print(f"per grid position (one raw and one unfolded image), {positions} positions:")
        print_figures(figures, floor)
        same = all(
            p.read_bytes() == (folder / "jobs2" / p.relative_to(folder / "jobs1")).read_bytes()
            for p in (folder / "jobs1").rglob("*")
            if p.is_file()
        )
        speed_up = figures["generation, jobs=1"][1] / figures["generation, jobs=2"][1]
        print(f"speed-up with 2 jobs: {speed_up:.2f}x; identical bytes: {same}")
    print(load())
    return 0


if __name__ == "__main__":
    sys.exit(main())
