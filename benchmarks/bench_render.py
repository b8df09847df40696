"""Render speed of generated worlds: build time, then per-pose time per stage and image kind.

Runs on one core (cv2 threads pinned to 1) and prints figures; no assertions. Usage:

    python benchmarks/bench_render.py [--seed 0] [--variant original] [--poses 12]
"""

from __future__ import annotations

import argparse
import time

import cv2
import numpy as np

from homebench.data.synth.spec import VARIANTS, WorldSpec
from homebench.data.synth.world import RAW_SUPERSAMPLE, build_world, position_noise_seed
from homebench.imaging.projection import fold


def _timed(fn, *args):
    start = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variant", choices=VARIANTS, default="original")
    parser.add_argument("--poses", type=int, default=12)
    args = parser.parse_args()
    cv2.setNumThreads(1)

    spec = WorldSpec(seed=args.seed, variant=args.variant)
    world, build = _timed(build_world, spec)
    grid = spec.to_grid()
    rng = np.random.default_rng(0)
    picks = [tuple(int(v) for v in rng.integers(0, grid.shape)) for _ in range(args.poses)]
    world.render(spec.pose(0, 0), 0)  # warm the projection map caches

    stages: dict[str, list[float]] = {
        "cast + shade (shared)": [],
        "unfolded: downsample": [],
        "raw: fold": [],
        "render, both kinds + noise": [],
    }
    for i, j in picks:
        pose = spec.pose(i, j)
        (hi, _), t_cast = _timed(world.panorama, pose)
        _, t_unfolded = _timed(world.downsample, hi)
        _, t_raw = _timed(fold, hi, world.panorama_geometry, world.raw_geometry, RAW_SUPERSAMPLE)
        _, t_total = _timed(world.render, pose, position_noise_seed(spec.seed, i, j))
        for stage, seconds in zip(
            stages.values(), (t_cast, t_unfolded, t_raw, t_total), strict=True
        ):
            stage.append(seconds)

    g = world.panorama_geometry
    print(
        f"world {spec.key()} seed={spec.seed} variant={spec.variant}: "
        f"{len(world.scene.objects)} objects, atlas {world.atlas.levels[0].shape}, "
        f"cast panorama {g.width} x {g.height}"
    )
    print(f"build (one per process and spec): {build * 1000:8.1f} ms")
    for key, values in stages.items():
        print(
            f"{key:>28s}: {np.median(values) * 1000:8.1f} ms median, "
            f"{np.max(values) * 1000:8.1f} ms max over {len(values)} poses (1 core)"
        )
    per_pose = float(np.median(stages["render, both kinds + noise"]))
    total = build + grid.size * per_pose
    print(f"estimated {grid.size}-position database, both kinds: {total:.1f} s on 1 core")


if __name__ == "__main__":
    main()
