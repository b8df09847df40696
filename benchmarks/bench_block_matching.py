"""Block-matching's block search against a compiled floor and against the numpy search it
replaced, on the generated world's bands, one thread.

Per pair (goal (5, 9) of synth-original against its first ``--pairs`` currents, block-matching
at its defaults: 96 blocks of 7 x 7, 61 x 7 displacements): process CPU and wall ms of

- ``home`` (the search, the vector sum, the checks);
- the compiled search alone (:func:`homebench.methods.block_matching.method.block_flow`);
- the floor: OpenCV's ``matchTemplate`` (squared differences, float32: it takes no float64)
  of each block against its search window, one call per block, as a user would write it;
- the numpy search the compiled one replaced (``reference_flow`` of
  tests/test_block_matching.py; its flow is checked equal to the compiled one's);

each with its ratio to the floor; best of 3 rounds, the load average before and after.

Run: ``python benchmarks/bench_block_matching.py [--pairs 24]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the reference search
from test_block_matching import reference_flow  # noqa: E402
from timing import as_in_job_workers, cpu_and_wall, load, print_figures  # noqa: E402

from homebench.data.catalog import ensure_generated  # noqa: E402
from homebench.methods.block_matching.method import BlockMatching, block_flow, displacements  # noqa: E402

GOAL = (5, 9)


def floor_windows(
    method: BlockMatching, current: np.ndarray, goal: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """(block, search window) float32 pairs of the floor: each block of ``current`` and the
    goal band's columns it is compared with (wrapped), all rows."""
    n, half, reach = method.n_columns, method.block_size // 2, method.search_radius
    top = method.vertical_radius
    wide = goal[:, (np.arange(n + 2 * half + 2 * reach) - half - reach) % n]
    pairs = []
    for centre in range(0, n, method.block_step):
        columns = (centre - half + np.arange(method.block_size)) % n
        block = current[top : top + method.block_size, columns]
        window = wide[:, centre : centre + method.block_size + 2 * reach]
        pairs.append((block.astype(np.float32), np.ascontiguousarray(window, dtype=np.float32)))
    return pairs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=24)
    args = parser.parse_args()
    as_in_job_workers()
    cv2.setNumThreads(1)
    method = BlockMatching()
    database = ensure_generated("synth-original")
    shape = database.grid.shape
    positions = [(i, j) for i in range(shape[0]) for j in range(shape[1]) if (i, j) != GOAL]
    goal = method.describe(database.view(*GOAL, "unfolded"))
    currents = [method.describe(database.view(i, j, "unfolded")) for i, j in positions]
    currents = currents[: args.pairs]
    centres = np.arange(0, method.n_columns, method.block_step)
    candidates = displacements(method.search_radius, method.vertical_radius)
    search = (method.block_size, centres, candidates)
    windows = [floor_windows(method, current, goal) for current in currents]
    for current in currents:
        np.testing.assert_array_equal(
            block_flow(current, goal, *search), reference_flow(current, goal, *search)
        )
    n = len(currents)
    print(f"per pair, {n} pairs; {load()}")

    def each(function):  # noqa: ANN001, ANN202
        return lambda: [function(k) for k in range(n)]

    figures = {
        "floor: cv2.matchTemplate per block": each(
            lambda k: [cv2.matchTemplate(w, b, cv2.TM_SQDIFF) for b, w in windows[k]]
        ),
        "home": each(lambda k: method.home(currents[k], goal)),
        "compiled search (block_flow)": each(lambda k: block_flow(currents[k], goal, *search)),
        "numpy search (before)": each(lambda k: reference_flow(currents[k], goal, *search)),
    }
    timed = {}
    for label, function in figures.items():
        cpu, wall = cpu_and_wall(function, 1)
        timed[label] = (cpu / n, wall / n)
    print_figures(timed, "floor: cv2.matchTemplate per block")
    print(f"after: {load()}")


if __name__ == "__main__":
    main()
