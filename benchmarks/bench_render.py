"""Render speed of generated worlds: build time, then per-pose time per stage and image kind.

Runs on one core (cv2 threads pinned to 1) and prints, per stage, the median process CPU and
wall time over the poses and the CPU time over a floor measured in the same process: one
bilinear ``cv2.remap`` of an image the size of the cast panorama (a smooth map, one look-up
per pixel, as the cast's texture reads are); the load average before and after. Usage:

    python benchmarks/bench_render.py [--seed 0] [--variant original] [--poses 12]
"""

from __future__ import annotations

import argparse

import cv2
import numpy as np
from timing import cpu_and_wall, load, print_figures, timed

from homebench.data.synth.spec import VARIANTS, WorldSpec
from homebench.data.synth.world import RAW_SUPERSAMPLE, build_world, position_noise_seed
from homebench.imaging.projection import fold


def _median(times: list[tuple[float, float]]) -> tuple[float, float]:
    cpu, wall = zip(*times, strict=True)
    return float(np.median(cpu)), float(np.median(wall))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variant", choices=VARIANTS, default="original")
    parser.add_argument("--poses", type=int, default=12)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print(load())

    spec = WorldSpec(seed=args.seed, variant=args.variant)
    world, build = timed(build_world, spec)
    grid = spec.to_grid()
    rng = np.random.default_rng(0)
    picks = [tuple(int(v) for v in rng.integers(0, grid.shape)) for _ in range(args.poses)]
    world.render(spec.pose(0, 0), 0)  # warm the projection map caches

    stages: dict[str, list[tuple[float, float]]] = {
        "cast + shade (shared)": [],
        "unfolded: downsample": [],
        "raw: fold": [],
        "render, both kinds + noise": [],
    }
    for i, j in picks:
        pose = spec.pose(i, j)
        (hi, _), cast = timed(world.panorama, pose)
        _, unfolded = timed(world.downsample, hi)
        _, raw = timed(fold, hi, world.panorama_geometry, world.raw_geometry, RAW_SUPERSAMPLE)
        _, total = timed(world.render, pose, position_noise_seed(spec.seed, i, j))
        for stage, times in zip(stages.values(), (cast, unfolded, raw, total), strict=True):
            stage.append(times)

    g = world.panorama_geometry
    hi, _ = world.panorama(spec.pose(0, 0))
    rows, columns = np.mgrid[0 : hi.shape[0], 0 : hi.shape[1]].astype(np.float32) + 0.5
    floor = f"floor: bilinear cv2.remap of {g.width} x {g.height}"
    figures = {floor: cpu_and_wall(lambda: cv2.remap(hi, columns, rows, cv2.INTER_LINEAR), 20)}
    figures |= {f"{stage} (median)": _median(times) for stage, times in stages.items()}
    print(
        f"world {spec.key()} seed={spec.seed} variant={spec.variant}: "
        f"{len(world.scene.objects)} objects, atlas {world.atlas.levels[0].shape}, "
        f"cast panorama {g.width} x {g.height}, {len(picks)} poses, 1 core"
    )
    print(f"  build (one per process and spec): {build[0]:.2f} s CPU, {build[1]:.2f} s wall")
    print_figures(figures, floor)
    slowest = max(wall for _, wall in stages["render, both kinds + noise"])
    per_pose = figures["render, both kinds + noise (median)"][1]
    print(f"  slowest render: {1000 * slowest:.1f} ms wall")
    total = build[1] + grid.size * per_pose
    print(f"estimated {grid.size}-position database, both kinds: {total:.1f} s on 1 core")
    print(load())


if __name__ == "__main__":
    main()
