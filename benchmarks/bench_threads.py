"""Every method in a plain process beside a pinned one: per-call CPU and wall, and the ratios.

A user's script or notebook calls homebench's methods in the environment it has, without the
thread variables a run's job workers set (:mod:`homebench.methods.threads` limits homebench's
own calls instead). Each round runs this script's child twice, alternated:

- **plain**: the environment without any thread variable
  (:data:`~homebench.evaluation.isolation.THREAD_LIMITS` removed), OpenCV's defaults;
- **pinned**: those variables at 1 and OpenCV on one thread, as the job workers run.

The child times every built-in method at its defaults on the generated 10 x 17 world
(``synth-original``): goal (5, 9) and the first ``--pairs`` other positions, after one untimed
call of each kind (a process's one-off costs). Per call: ``describe`` with loading the view
(per image), ``home`` (per pair; DID gets its current view's grid neighbours, klt-sector an
empty route) and ``home_many`` (per pair: the method's batch call, or ``home`` pair by pair
where it has none, as :func:`homebench.methods.base.home_many`). Printed: the medians over the
rounds of per-call process CPU and wall ms, plain and pinned, their ratios (target: plain at
most 1.2 x pinned) and each child's 1-minute load average when it started; then the limit's own
cost per call (wall microseconds of a limited call that does nothing: outermost, and within
another such call).

Run: ``python benchmarks/bench_threads.py [--rounds 3] [--pairs 24] [--methods NAME ...]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

from homebench.evaluation.isolation import THREAD_LIMITS

DATABASE = "synth-original"
GOAL = (5, 9)
CALLS = ("describe", "home", "home_many")
MODES = ("plain", "pinned")


def _per_call(function: Callable[[], object], calls: int) -> tuple[float, float]:
    """Process CPU and wall ms per call of ``function()`` making ``calls`` calls, best of 3."""
    best = (float("inf"), float("inf"))
    for _ in range(3):
        cpu, wall = time.process_time(), time.perf_counter()
        function()
        spent = (time.process_time() - cpu, time.perf_counter() - wall)
        best = min(best, (1e3 * spent[0] / calls, 1e3 * spent[1] / calls))
    return best


def child(mode: str, names: list[str], pairs: int) -> None:
    """Print one JSON line: ``{method: {call: [cpu ms, wall ms]}}`` (see the module)."""
    import cv2

    from homebench.data.catalog import ensure_generated
    from homebench.methods import registry
    from homebench.methods.base import home_many

    if mode == "pinned":
        cv2.setNumThreads(1)
    database = ensure_generated(DATABASE)
    shape = database.grid.shape
    positions = [(i, j) for i in range(shape[0]) for j in range(shape[1]) if (i, j) != GOAL]
    currents = positions[:pairs]
    figures: dict[str, dict[str, tuple[float, float]]] = {}
    for name in names:
        method = registry.create(name)
        kind = method.image_kind

        def describe_all(method=method, kind=kind) -> list:
            return [method.describe(database.view(i, j, kind)) for i, j in currents]

        features = describe_all()
        goal = method.describe(database.view(*GOAL, kind))
        extra = _extra(method, database, currents)
        one = {k: v[0] for k, v in extra.items()}
        method.home(features[0], goal, **one)

        def home_each(m=method, f=features, g=goal, e=extra) -> None:
            for k, current in enumerate(f):
                m.home(current, g, **{key: values[k] for key, values in e.items()})

        figures[name] = {
            "describe": _per_call(describe_all, len(currents)),
            "home": _per_call(home_each, len(currents)),
            "home_many": _per_call(
                lambda m=method, f=features, g=goal, e=extra: home_many(m, f, g, **e),
                len(currents),
            ),
        }
    figures["limit"] = _limit_cost()
    print(json.dumps(figures))


def _limit_cost(calls: int = 20000) -> dict[str, tuple[float, float]]:
    """Wall microseconds per call of a limited no-op, outermost and nested (as CPU, wall)."""
    from homebench.methods.threads import single_threaded

    nothing = single_threaded(lambda: None)

    @single_threaded
    def nested() -> None:
        for _ in range(calls):
            nothing()

    def outermost() -> None:
        for _ in range(calls):
            nothing()

    return {
        kind: tuple(1e3 * v for v in _per_call(function, calls))
        for kind, function in (("outermost", outermost), ("nested", nested))
    }


def _extra(method: Any, database: Any, currents: list[tuple[int, int]]) -> dict[str, list]:
    """What ``home`` takes beyond the two features, one per current: DID's grid neighbours
    ((offset in metres, features) of those inside the grid), klt-sector's route (empty: the
    direct pair)."""
    if getattr(method, "uses_neighbours", False):
        grid = database.grid
        steps = ((1, 0), (-1, 0), (0, 1), (0, -1))
        return {
            "neighbours": [
                [
                    (
                        grid.position(a, b) - grid.position(i, j),
                        method.describe(database.view(a, b, method.image_kind)),
                    )
                    for a, b in ((i + di, j + dj) for di, dj in steps)
                    if 0 <= a < grid.shape[0] and 0 <= b < grid.shape[1]
                ]
                for i, j in currents
            ]
        }
    if getattr(method, "uses_route", False):
        return {"route": [[] for _ in currents]}
    return {}


def environment(mode: str) -> dict[str, str]:
    """The child's environment: this one without the thread variables, or with them at 1."""
    plain = {k: v for k, v in os.environ.items() if k not in THREAD_LIMITS}
    return plain if mode == "plain" else {**plain, **dict.fromkeys(THREAD_LIMITS, "1")}


def run_child(mode: str, names: list[str], pairs: int) -> tuple[dict, float]:
    """One child's figures and the 1-minute load average when it started."""
    load = os.getloadavg()[0]
    command = [sys.executable, __file__, "--child", mode, "--pairs", str(pairs), "--methods"]
    done = subprocess.run(
        command + names, env=environment(mode), capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.splitlines()[-1]), load


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--pairs", type=int, default=24)
    parser.add_argument("--methods", nargs="+")
    parser.add_argument("--child", choices=MODES, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.methods, args.pairs)
        return
    from homebench.data.catalog import ensure_generated
    from homebench.methods import registry

    ensure_generated(DATABASE, jobs=2)
    names = args.methods or [
        name
        for name, cls in registry.available().items()
        if cls.__module__.startswith("homebench.")
    ]
    runs: dict[str, list[dict]] = {mode: [] for mode in MODES}
    for round_ in range(args.rounds):
        for mode in MODES:
            figures, load = run_child(mode, names, args.pairs)
            runs[mode].append(figures)
            print(f"round {round_ + 1} {mode:6s}: load {load:.2f}", flush=True)
    print(f"medians over {args.rounds} rounds, per call, ms; ratio: plain / pinned (the floor)")
    print(f"{'method':16s} {'call':10s} {'CPU plain':>9s} {'pinned':>8s} {'ratio':>6s} "
          f"{'wall plain':>10s} {'pinned':>8s} {'ratio':>6s}")  # fmt: skip
    for name in names:
        for call in CALLS:
            cpu, wall = (
                [statistics.median(r[name][call][k] for r in runs[mode]) for mode in MODES]
                for k in (0, 1)
            )
            print(
                f"{name:16s} {call:10s} {cpu[0]:9.3f} {cpu[1]:8.3f} {cpu[0] / cpu[1]:6.2f} "
                f"{wall[0]:10.3f} {wall[1]:8.3f} {wall[0] / wall[1]:6.2f}"
            )
    for kind in ("outermost", "nested"):
        cost = [statistics.median(r["limit"][kind][1] for r in runs[mode]) for mode in MODES]
        print(f"the limit's own cost, {kind} call: {cost[0]:.2f} us plain, {cost[1]:.2f} pinned")
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
