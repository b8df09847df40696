"""Per-pair CPU time of every built-in method on unfolded panoramas, against image width.

For each method and width: the process CPU time and the wall time per ``describe`` (one
image) and per ``home`` (one pair, features given), one thread, and each home time's ratio to
a floor measured in the same process at the same width: the sum of squared differences of two
float64 images of the panorama's size (the least any method comparing two images does). The
ratio stays meaningful on a busy machine; the load average is printed before and after.
Images: a smooth random panorama and the same turned by a tenth of a turn with noise; DID gets
the four neighbours it gets on a grid (here the current view rolled by a column each way);
sift runs on raw images and is in ``bench_sift.py``.

Run: ``python benchmarks/bench_baselines.py [--widths 144 288 576] [--repeats N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from homebench.geometry import PanoramaGeometry  # noqa: E402
from homebench.methods import registry  # noqa: E402
from homebench.methods.base import View  # noqa: E402

cv2.setNumThreads(1)


def _geometry(width: int) -> PanoramaGeometry:
    """A panorama of ``width`` columns with square pixels from -40 to +40 deg."""
    return PanoramaGeometry.square_pixels(width, math.radians(40.0), math.radians(-40.0))


def _views(width: int, seed: int = 0) -> tuple[View, View]:
    geometry = _geometry(width)
    rng = np.random.default_rng(seed)
    half = width // 2 + 1
    spectrum = rng.normal(size=(geometry.height, half)) * np.exp(-np.arange(half) / (width / 24))
    image = np.fft.irfft(spectrum, n=width, axis=1)
    image = 128.0 + 60.0 * image / np.std(image)
    goal = np.clip(image, 0, 255).astype(np.uint8)
    turned = np.roll(image, width // 10, axis=1) + rng.normal(0, 3, image.shape)
    return View(np.clip(turned, 0, 255).astype(np.uint8), geometry), View(goal, geometry)


def cpu_and_wall(function: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Best-of-3 (process CPU, wall) seconds per call over ``repeats`` calls, after a warm-up."""
    function()
    best = (math.inf, math.inf)
    for _ in range(3):
        cpu, wall = time.process_time(), time.perf_counter()
        for _ in range(repeats):
            function()
        found = ((time.process_time() - cpu) / repeats, (time.perf_counter() - wall) / repeats)
        best = min(best, found)
    return best


def _extra(method: object, current: View) -> dict[str, object]:
    """The views beyond the pair that a method takes (DID's neighbours, a route)."""
    if getattr(method, "uses_neighbours", False):
        rolled = [View(np.roll(current.image, s, axis=1), current.geometry) for s in (1, -1)]
        offsets = [np.array(v) for v in ((0.3, 0.0), (-0.3, 0.0), (0.0, 0.3), (0.0, -0.3))]
        return {"neighbours": [(o, method.describe(rolled[k % 2])) for k, o in enumerate(offsets)]}
    if getattr(method, "uses_route", False):
        return {"route": []}
    return {}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--widths", type=int, nargs="+", default=[144, 288, 576])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    names = sorted(
        name
        for name, cls in registry.available().items()
        if cls.__module__.startswith("homebench.") and cls.image_kind == "unfolded"
    )
    print(f"load average before: {os.getloadavg()}")
    print(f"{'method':16} {'width':>5} {'describe cpu':>13} {'home cpu':>10} {'home wall':>10}"
          f" {'floor':>9} {'home/floor':>10}")  # fmt: skip
    for width in args.widths:
        current, goal = _views(width)
        a = current.image.astype(np.float64)
        b = goal.image.astype(np.float64)
        floor, _ = cpu_and_wall(lambda a=a, b=b: float(np.sum((a - b) ** 2)), 200)
        for name in names:
            method = registry.create(name)
            describe, _ = cpu_and_wall(lambda m=method, v=current: m.describe(v), args.repeats)
            features = method.describe(current), method.describe(goal)
            extra = _extra(method, current)
            home_cpu, home_wall = cpu_and_wall(
                lambda m=method, f=features, e=extra: m.home(*f, **e), args.repeats
            )
            print(
                f"{name:16} {width:5d} {describe * 1e3:10.2f} ms {home_cpu * 1e3:7.2f} ms "
                f"{home_wall * 1e3:7.2f} ms {floor * 1e3:6.3f} ms {home_cpu / floor:10.0f}"
            )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
