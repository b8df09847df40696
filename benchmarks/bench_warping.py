"""Per-pair timing of warping and min-warping on 288-column panoramas, one thread.

Prints describe and home times per call and the speed-up over a reference computation kept
here: for warping, the direct search (interpolate the warped goal and sum squared differences for
every (rho, alpha, psi) separately); for min-warping, the search without the run-minimum trick
(every admissible (scale plane, current column) pair of every goal column looked up). Each
reference must find the same optimum. Targets: warping (20 x 72 x 72) under 5 ms per pair;
min-warping (96 x 96, 9 planes) within 3x of ~10 ms (Möller's SIMD C++: 1.9 ms distance stack
+ 8.1 ms search).

Run: ``python benchmarks/bench_warping.py [--repeats N]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from timing import per_call  # noqa: E402

from homebench.geometry import TWO_PI, PanoramaGeometry  # noqa: E402
from homebench.methods.base import View  # noqa: E402
from homebench.methods.min_warping import MinWarping, search_runs  # noqa: E402
from homebench.methods.warping import Warping  # noqa: E402

GEOMETRY = PanoramaGeometry(288, 96, math.radians(40.0), math.radians(-40.0))


def _views(seed: int = 0) -> tuple[View, View]:
    """A smooth random panorama and the same turned by 37 columns, with noise."""
    rng = np.random.default_rng(seed)
    spectrum = rng.normal(size=(GEOMETRY.height, GEOMETRY.width // 2 + 1)) * np.exp(
        -np.arange(GEOMETRY.width // 2 + 1) / 12.0
    )
    image = np.fft.irfft(spectrum, n=GEOMETRY.width, axis=1)
    image = 128.0 + 60.0 * image / np.std(image)
    goal = np.clip(image, 0, 255).astype(np.uint8)
    current = np.clip(np.roll(image, 37, axis=1) + rng.normal(0, 3, image.shape), 0, 255)
    return View(current.astype(np.uint8), GEOMETRY), View(goal, GEOMETRY)


def warping_reference(method: Warping, current: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Direct search: cost (n_rho, n_alpha, n_psi), one warped prediction per parameter triple."""
    n = method.n_columns
    theta_prime = TWO_PI * np.arange(n) / n
    support, periodic = np.arange(n + 1), np.append(goal, goal[0])  # interpolation on [0, n]
    cost = np.empty((method.n_rho, method.n_alpha, method.n_psi))
    for r, rho in enumerate(method.rho):
        for a in range(method.n_alpha):
            alpha = TWO_PI * a / method.n_alpha
            for p in range(method.n_psi):
                phi = theta_prime + TWO_PI * p / method.n_psi
                theta = (phi - np.arcsin(rho * np.sin(phi - alpha))) % TWO_PI
                predicted = np.interp(theta * n / TWO_PI, support, periodic)
                cost[r, a, p] = np.sum((current - predicted) ** 2)
    return cost


def min_warping_reference(method: MinWarping, distances: np.ndarray) -> np.ndarray:
    """Search without run minima: every admissible pair looked up, cost (n_alpha, n_psi)."""
    n = method.n_columns
    runs = search_runs(n, method.n_scales, method.max_scale)
    a = np.arange(n)[None, :, None]
    p = np.arange(n)[None, None, :]
    cost = np.zeros((n, n))
    for row, x in enumerate(runs.x):
        pairs = [
            (runs.plane[row, q], runs.start[row, q] + t)
            for q in range(runs.count[row])
            for t in range(runs.length[row, q])
        ]
        plane, y = (np.array(v)[:, None, None] for v in zip(*pairs, strict=True))
        cost += distances[plane, (x + a) % n, (y + a - p) % n].min(axis=0)
    return cost


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    repeats = parser.parse_args().repeats
    current_view, goal_view = _views()

    warping = Warping()
    current, goal = warping.describe(current_view), warping.describe(goal_view)
    t_describe = per_call(lambda: warping.describe(current_view), repeats)
    t_home = per_call(lambda: warping.home(current, goal), repeats)
    start = time.perf_counter()
    reference = warping_reference(warping, current, goal)
    t_reference = time.perf_counter() - start
    same = np.argmin(reference) == np.argmin(warping.costs(current, goal))
    print(f"warping      ({warping.n_rho} x {warping.n_alpha} x {warping.n_psi})")
    print(f"  describe   {t_describe * 1e3:8.2f} ms")
    print(f"  home       {t_home * 1e3:8.2f} ms   (target < 5 ms)")
    print(f"  reference  {t_reference * 1e3:8.1f} ms   direct search: {t_reference / t_home:.0f}x")
    print(f"  same optimum as the reference: {same}")

    minw = MinWarping()
    search_runs(minw.n_columns, minw.n_scales, minw.max_scale)  # one-off table, cached
    current, goal = minw.describe(current_view), minw.describe(goal_view)
    distances = minw.distance_stack(current, goal)
    t_describe = per_call(lambda: minw.describe(current_view), repeats)
    t_stack = per_call(lambda: minw.distance_stack(current, goal), repeats)
    t_search = per_call(lambda: minw.costs(distances), repeats)
    t_home = per_call(lambda: minw.home(current, goal), repeats)
    start = time.perf_counter()
    reference = min_warping_reference(minw, distances)
    t_reference = time.perf_counter() - start
    fast = minw.costs(distances)
    same = np.argmin(reference) == np.argmin(fast) and np.allclose(reference, fast, rtol=1e-5)
    print(f"min-warping  ({minw.n_columns} x {minw.n_columns}, {minw.n_scales} scale planes)")
    print(f"  describe   {t_describe * 1e3:8.2f} ms")
    print(f"  stack      {t_stack * 1e3:8.2f} ms   (Möller SIMD: 1.9 ms)")
    print(f"  search     {t_search * 1e3:8.2f} ms   (Möller SIMD: 8.1 ms)")
    print(f"  home       {t_home * 1e3:8.2f} ms   (target within 3x of 10 ms)")
    print(
        f"  reference  {t_reference * 1e3:8.1f} ms   pairwise search: {t_reference / t_search:.1f}x"
    )
    print(f"  same costs as the reference: {same}")


if __name__ == "__main__":
    main()
