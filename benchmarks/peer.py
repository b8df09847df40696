"""Side by side with Möller's C++ WarpingSIMD (imported as ``import peer`` by
``bench_min_warping.py`` and ``bench_warping_2d.py``): the world, alternated rounds, the peer.

**World.** A generated 10 x 17 grid (seed 0, 0.30 m apart) of 288 x 72 unfolded panoramas
(+-45 deg); goal (5, 9) against every other position, as a job runs them. AE is taken over the
pairs with an estimate; pairs without one are counted.

**Rounds.** Figures are process CPU time per pair (``time.process_time``; the peer's
``CLOCK_PROCESS_CPUTIME_ID``) and wall time, measured in alternated rounds (every figure once
per round, in the same order), with the 1-minute load average at the start of each; the
medians over the rounds are reported, ratios are CPU over CPU.

**The peer** is not part of homebench and nothing here builds it: fetch WarpingSIMD
(https://github.com/ti-uni-bielefeld/WarpingSIMD), build a small driver against it outside
this repository (e.g. ``g++ -O3 -funroll-loops -march=native``), and pass its path as
``--peer PATH``. The driver is called as::

    PATH METHOD DOUBLE FINE VERTRES HORIZON REPEATS GOAL.pgm CURRENT.pgm ...

``METHOD``: ``min`` (min-warping) or ``2d`` (2D-warping); ``DOUBLE``, ``FINE``: 0 or 1 (double
search, fine search); ``VERTRES``: elevation per image row (rad); ``HORIZON``: the row of
elevation 0 (0 = top row's centre); ``REPEATS``: timed passes over the currents after one
untimed pass; the images: 8-bit PGM panoramas, columns counter-clockwise (homebench's canonical
order, so beta = alpha - psi + pi). It prints one line ``pair K ALPHA PSI`` per current
(radians), then ``cpu_ms_per_pair X wall_ms_per_pair Y`` over the timed passes. The figures in
docs/measured/speed.md come from a driver with the settings of WarpingSIMD's
``warpingSIMDTest.C``: 96 x 96 steps, 9 scale planes up to 2, NSAD on edge-filtered images
(``firstPhaseNSAD2``, pixel scale 16, post scale 200), an 8-bit scale-plane stack summed into
16-bit match values, nearest-row magnification, the XPAY / PARX search loops, rho up to 1 in 20
steps for 2D-warping. The peer reads either homebench's band (``band``: the 16 rows from -15 to
+15 deg that homebench's methods read, rounded to 8 bits) or the whole panorama (``full``: 72
rows).
"""

from __future__ import annotations

import math
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from homebench.analysis.statistics import compare_ae
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import render_position
from homebench.evaluation.executors import PRELOAD
from homebench.evaluation.isolation import Crash, WorkerPool
from homebench.geometry import angular_error, home_direction
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, View

WORLD = WorldSpec(
    seed=0,
    grid={"shape": [10, 17]},
    unfolded={"width": 288, "elevation_top_deg": 45.0, "elevation_bottom_deg": -45.0},
)
GOAL = (5, 9)
#: The peer's images: rows, top and bottom elevation (deg) of each kind.
IMAGES = {"band": (16, 15.0, -15.0), "full": (72, 45.0, -45.0)}

Ij = tuple[int, int]


@dataclass(frozen=True)
class Figure:
    """One measurement: CPU and wall ms per pair, the estimates (home directions in the
    current robot frame, None: no estimate) and the 1-minute load average when it began."""

    cpu_ms: float
    wall_ms: float
    angles: tuple[float | None, ...]
    load: float


@cache
def views() -> dict[Ij, View]:
    """Every view of the world (rendered once, about 10 s)."""
    geometry = WORLD.unfolded.geometry()
    return {
        ij: View(render_position(WORLD, *ij)["unfolded"], geometry)
        for ij in WORLD.to_grid().indices()
    }


def currents(limit: int | None, goal: Ij = GOAL) -> list[Ij]:
    """The current positions of a goal's pairs (the first ``limit`` of them)."""
    others = [ij for ij in WORLD.to_grid().indices() if ij != goal]
    return others[:limit]


def spread_goals(count: int) -> list[Ij]:
    """``count`` goals spread evenly over the grid's positions (row-major), :data:`GOAL` first."""
    others = [ij for ij in WORLD.to_grid().indices() if ij != GOAL]
    picks = np.linspace(0, len(others) - 1, max(count - 1, 0)).round().astype(int)
    return [GOAL, *(others[k] for k in picks)][:count]


def errors(angles: tuple[float | None, ...], positions: list[Ij], goal: Ij = GOAL) -> np.ndarray:
    """AE (radians, NaN: no estimate) of each pair's home direction: shape (len(positions),)."""
    pose_goal = WORLD.pose(*goal)
    out = np.full(len(positions), np.nan)
    for k, (angle, ij) in enumerate(zip(angles, positions, strict=True)):
        if angle is not None:
            pose = WORLD.pose(*ij)
            truth = home_direction((pose.x, pose.y), (pose_goal.x, pose_goal.y), pose.heading)
            out[k] = angular_error(angle, truth)
    return out


def ae(angles: tuple[float | None, ...], positions: list[Ij]) -> tuple[float, int]:
    """Mean AE (deg) over the pairs of :data:`GOAL` with an estimate, and the pairs without."""
    found = errors(angles, positions)
    found = found[np.isfinite(found)]
    mean = float(np.degrees(found.mean())) if found.size else math.nan
    return mean, len(angles) - found.size


def load() -> float:
    """The 1-minute load average."""
    return float(Path("/proc/loadavg").read_text().split()[0])


def timed_pass(
    home: Callable[[Any, Any], HomingEstimate], currents: list[Any], goal: Any
) -> tuple[float, float, tuple[float | None, ...]]:
    """CPU and wall ms per pair of ``home(current, goal)`` over ``currents``, and the angles."""
    cpu, wall = time.process_time(), time.perf_counter()
    angles = tuple(home(current, goal).angle for current in currents)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return 1e3 * cpu / len(currents), 1e3 * wall / len(currents), angles


def method_pass(
    method: Any, currents: list[Any], goal: Any, goal_kept: bool = True
) -> tuple[float, float, tuple[float | None, ...]]:
    """:func:`timed_pass` of ``method.home`` after untimed calls that bear a process's one-off
    costs (its first call) and, if ``goal_kept``, what a method keeps of the goal (a job's
    first pair); otherwise the pass bears that (a job's pairs, per pair)."""
    method.home(currents[0], currents[-1])
    if goal_kept:
        method.home(currents[0], goal)
    return timed_pass(method.home, currents, goal)


def _pass_in_worker(item: tuple) -> tuple[float, float, tuple[float | None, ...]]:
    """:func:`method_pass` of ``(make, currents, goal, goal_kept)``, the method made here."""
    make, currents, goal, goal_kept = item
    return method_pass(make(), currents, goal, goal_kept)


class JobWorker:
    """One isolated job worker, as a run's (forked from a worker server that imported the
    method's ``preload_modules``; the job workers' allocator settings), kept for every round."""

    def __init__(self, preload: tuple[str, ...]):
        self.pool = WorkerPool(1, preload=(*PRELOAD, *preload))

    def method_pass(
        self, make: Callable[[], Any], currents: list[Any], goal: Any, goal_kept: bool = True
    ) -> tuple[float, float, tuple[float | None, ...]]:
        """:func:`method_pass` of a method made by ``make`` (picklable) in the worker."""
        item = (make, currents, goal, goal_kept)
        ((_, result),) = self.pool.map_unordered(_pass_in_worker, [item])
        if isinstance(result, Crash):
            raise SystemExit(f"the job worker failed: {result.cause}")
        return result

    def close(self) -> None:
        self.pool.close()


class Peer:
    """The peer's driver at ``path`` (see the module docstring), on PGM copies of the views;
    ``positions``: the currents of :data:`GOAL` that :meth:`run` times."""

    def __init__(self, path: Path, positions: list[Ij]):
        self.path, self.positions = path, positions
        self.scratch = tempfile.TemporaryDirectory(prefix="hb-peer-")  # removed at exit
        self.folder = Path(self.scratch.name)
        self.written: dict[tuple[str, Ij], str] = {}

    def images(self, kind: str, positions: list[Ij]) -> list[str]:
        """PGM paths of the views at ``positions``, as the peer reads them (``kind``), each
        written at its first use."""
        rows, top, bottom = IMAGES[kind]
        for ij in positions:
            if (kind, ij) in self.written:
                continue
            view = views()[ij]
            image = view.image
            if kind == "band":
                band = horizon_band(image, view.geometry, math.radians(bottom),
                                    math.radians(top), rows, image.shape[1])  # fmt: skip
                image = np.clip(np.rint(band), 0, 255).astype(np.uint8)
            path = self.folder / f"{kind}_{ij[0]}_{ij[1]}.pgm"
            cv2.imwrite(str(path), image)
            self.written[kind, ij] = str(path)
        return [self.written[kind, ij] for ij in positions]

    def run(
        self,
        method: str,
        searches: bool,
        kind: str,
        goal: Ij = GOAL,
        positions: list[Ij] | None = None,
    ) -> Figure:
        """One timed pass of the peer: ``method`` ``min`` or ``2d``, double and fine search on
        or off, on images of ``kind``, ``goal`` against ``positions`` (default: this peer's)."""
        positions = self.positions if positions is None else positions
        rows, top, bottom = IMAGES[kind]
        step = math.radians(top - bottom) / rows
        horizon = math.radians(top) / step - 0.5
        flag = str(int(searches))
        start = load()
        args = [
            method,
            flag,
            flag,
            repr(step),
            repr(horizon),
            "1",
            *self.images(kind, [goal, *positions]),
        ]
        out = subprocess.run(
            [str(self.path), *args], capture_output=True, text=True, check=True
        ).stdout.split("\n")
        lines = [line.split() for line in out if line.strip()]
        angles = tuple(
            float(alpha) - float(psi) + math.pi for _, _, alpha, psi in lines[:-1]
        )  # fmt: skip
        return Figure(float(lines[-1][1]), float(lines[-1][3]), angles, start)


def compare_over_goals(
    goals: list[Ij], make: Callable[[], Any], driver: Peer, method: str, kind: str = "band"
) -> None:
    """Print a paired comparison of the AE of homebench's ``make()`` and the peer's ``method``
    (double and fine search, images of ``kind``) on every pair of each goal in ``goals``:
    mean AE of each and of the difference with goal-bootstrap intervals (95 %), and the
    sign-flip test over goals (:func:`homebench.analysis.statistics.compare_ae`)."""
    ours, theirs, labels = [], [], []
    homing = make()
    described = {ij: homing.describe(view) for ij, view in views().items()}
    for goal in goals:
        positions = currents(None, goal)
        angles = tuple(homing.home(described[ij], described[goal]).angle for ij in positions)
        ours.append(errors(angles, positions, goal))
        theirs.append(
            errors(driver.run(method, True, kind, goal, positions).angles, positions, goal)
        )
        labels += [goal] * len(positions)
    result = compare_ae(np.concatenate(theirs), np.concatenate(ours), np.array(labels))
    deg = math.degrees
    print(f"AE over {len(goals)} goals ({len(labels)} pairs; no estimate counts as 90 deg), "
          "mean [95 % goal-bootstrap interval]:")  # fmt: skip
    for name, interval in (("homebench", result.mean_ae_b), ("peer", result.mean_ae_a),
                           ("homebench - peer", result.mean_ae)):  # fmt: skip
        print(f"  {name:17s} {deg(interval.estimate):6.3f} deg [{deg(interval.lo):.3f}, "
              f"{deg(interval.hi):.3f}]")  # fmt: skip
    print(f"  sign-flip test over goals: p = {result.p_goal:.3f}")


def alternate(rounds: int, figures: dict[str, Callable[[], Figure]]) -> dict[str, list[Figure]]:
    """Every figure once per round, in order, ``rounds`` times."""
    out: dict[str, list[Figure]] = {label: [] for label in figures}
    for _ in range(rounds):
        for label, measure in figures.items():
            out[label].append(measure())
    return out


def homebench_figure(pass_: Callable[[], tuple[float, float, tuple]]) -> Callable[[], Figure]:
    """A figure of a homebench pass (:func:`method_pass` or :meth:`JobWorker.method_pass`)."""

    def measure() -> Figure:
        start = load()
        cpu, wall, angles = pass_()
        return Figure(cpu, wall, angles, start)

    return measure


def report(results: dict[str, list[Figure]], positions: list[Ij], bases: dict[str, str]) -> None:
    """Print each figure's median CPU and wall ms per pair, its AE, its CPU over the median CPU
    of each figure in ``bases`` (column name -> label; absent labels give no column) and its
    rounds with their loads."""
    bases = {name: label for name, label in bases.items() if label in results}
    medians = {label: statistics.median(f.cpu_ms for f in runs) for label, runs in results.items()}
    width = max(len(label) for label in results)
    ratios = "".join(f" {name:>10s}" for name in bases)
    print(f"  {'per pair, median':{width}s} {'CPU ms':>7s} {'wall ms':>8s} {'AE deg':>6s} "
          f"{'none':>4s}{ratios}  CPU ms by round (load average at its start)")  # fmt: skip
    for label, runs in results.items():
        wall = statistics.median(f.wall_ms for f in runs)
        error, missing = ae(runs[0].angles, positions) if runs[0].angles else (math.nan, 0)
        ratios = "".join(f" {medians[label] / medians[base]:10.2f}" for base in bases.values())
        rounds = ", ".join(f"{f.cpu_ms:.2f} ({f.load:.1f})" for f in runs)
        print(
            f"  {label:{width}s} {medians[label]:7.2f} {wall:8.2f} {error:6.2f} {missing:4d}"
            f"{ratios}  {rounds}"
        )
