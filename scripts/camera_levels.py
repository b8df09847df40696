"""The horizon band's grey levels of every style and variant, fixed against auto exposure.

For each world style and variant (seed 0 unless given), renders three grid positions with
the camera's auto-exposure and with a fixed exposure (the reference time 0.6, which exposes
the poster room's original light like the auto-exposure does) and prints, as a Markdown
table, the mean and the 5 / 95 % levels of the +-10 deg horizon band, the share of it that
is saturated, and the auto-exposure's time x gain. Run by hand:

    python scripts/camera_levels.py [--seed 0] [--styles posters lab corridor outdoor]
"""

from __future__ import annotations

import argparse

import numpy as np

from homebench.data.synth.camera import CameraSpec
from homebench.data.synth.spec import STYLES, VARIANTS, WorldSpec
from homebench.data.synth.world import build_world, position_noise_seed
from homebench.imaging.horizon import horizon_band

POSITIONS = ((1, 4), (5, 9), (8, 13))
BAND_DEG = 10.0


def band_levels(spec: WorldSpec) -> tuple[np.ndarray, float]:
    """The horizon band's grey levels at POSITIONS (flattened) and the mean time x gain."""
    world = build_world(spec)
    geometry = world.unfolded_geometry
    values, exposures = [], []
    for i, j in POSITIONS:
        pose = spec.pose(i, j)
        image = world.render(pose, position_noise_seed(spec.seed, i, j))["unfolded"]
        half = np.radians(BAND_DEG)
        values.append(horizon_band(image, geometry, -half, half, 20, geometry.width).ravel())
        exposure = world.capture(pose)[1]
        exposures.append(exposure.time * exposure.gain)
    return np.concatenate(values), float(np.mean(exposures))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--styles", nargs="*", default=list(STYLES))
    args = parser.parse_args()
    print("| style | variant | fixed: mean, 5-95 %, saturated | auto: mean, 5-95 %, saturated "
          "| auto t x g |")  # fmt: skip
    print("| --- | --- | --- | --- | --- |")
    for style in args.styles:
        for variant in VARIANTS:
            cells = []
            for camera in (CameraSpec(exposure="fixed"), CameraSpec()):
                spec = WorldSpec(seed=args.seed, style=style, variant=variant, camera=camera)
                v, product = band_levels(spec)
                p5, p95 = np.percentile(v, [5, 95])
                cells.append(f"{v.mean():.0f}, {p5:.0f}-{p95:.0f}, {np.mean(v >= 254.5):.1%}")
            print(f"| {style} | {variant} | {cells[0]} | {cells[1]} | {product:.2f} |")


if __name__ == "__main__":
    main()
