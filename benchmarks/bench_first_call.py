"""A plain process's first call of each compiled method, with numba's cache warm, against the
floor: numba's own set-up.

Each method runs in a fresh child process without the thread variables (a user's script), the
numba cache warmed by an untimed child first. The child imports homebench's methods and numpy
(not counted), then numba alone (its import: the same for every method), then makes the
method's first ``describe`` and ``home`` on two views of the generated world (synth-original,
(4, 9) against goal (5, 9)), then a second ``home``. The floor is a child that, after numba's
import, loads one trivial kernel from the cache (:mod:`homebench.methods.jit_setup`): numba's
set-up, which any first compiled call pays (its target context, and scipy.linalg, which numba
imports to find a BLAS). Printed per method: process CPU and wall seconds of numba's import, of
the first call (setting numba up, loading the kernels the method uses, the method's own one-off
work) and of the second ``home``; the first call's CPU over the floor's; the kernel modules the
process then holds; the 1-minute load average when the child started.

Run: ``python benchmarks/bench_first_call.py [--methods NAME ...] [--params KEY=VALUE ...]``
(``--params`` for every method, e.g. ``scheme=scale-planes`` for warping-2d).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable

from homebench.evaluation.isolation import THREAD_LIMITS

METHODS = ("min-warping", "warping-2d", "block-matching", "klt-sector")
FLOOR = "floor"
DATABASE = "synth-original"
PAIR = ((4, 9), (5, 9))  # current, goal


def _first_call(name: str, params: dict[str, str]) -> tuple[Callable[[], object], ...]:
    """The child's first call and second call (the floor: the set-up, and nothing)."""
    if name == FLOOR:
        import importlib

        return (lambda: importlib.import_module("homebench.methods.jit_setup"), lambda: None)
    import yaml

    from homebench.data.catalog import ensure_generated
    from homebench.methods import registry

    database = ensure_generated(DATABASE)
    method = registry.create(name, **{k: yaml.safe_load(v) for k, v in params.items()})
    views = [database.view(i, j, method.image_kind) for i, j in PAIR]
    extra = {"route": []} if getattr(method, "uses_route", False) else {}
    features: list = []

    def first() -> None:
        features.extend(method.describe(view) for view in views)
        method.home(*features, **extra)

    return first, lambda: method.home(*features, **extra)


def child(name: str, params: dict[str, str]) -> None:
    """Print one JSON line of figures (see the module docstring)."""
    import numpy  # noqa: F401  (not counted)

    import homebench.methods  # noqa: F401

    first, second = _first_call(name, params)
    marks = [(time.process_time(), time.perf_counter())]
    import numba  # noqa: F401  (its import, timed alone)

    marks.append((time.process_time(), time.perf_counter()))
    for call in (first, second):
        call()
        marks.append((time.process_time(), time.perf_counter()))
    spent = [[b[k] - a[k] for k in (0, 1)] for a, b in zip(marks, marks[1:], strict=False)]
    kernels = sorted(m for m in sys.modules if m.startswith("homebench.") and "kernels" in m)
    print(json.dumps({"spent": spent, "kernels": kernels}))


def run_child(name: str, params: list[str]) -> tuple[dict, float]:
    """One fresh plain child's figures, and the 1-minute load average when it started."""
    load = os.getloadavg()[0]
    environment = {k: v for k, v in os.environ.items() if k not in THREAD_LIMITS}
    command = [sys.executable, __file__, "--child", name, "--params", *params]
    done = subprocess.run(command, env=environment, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.splitlines()[-1]), load


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", nargs="+", default=list(METHODS))
    parser.add_argument("--params", nargs="*", default=[])
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, dict(p.split("=", 1) for p in args.params))
        return
    print("process CPU / wall seconds; first call's CPU over the floor's (numba's set-up)")
    print(f"{'':16s} {'numba import':>13s} {'first call':>13s} {'second':>13s} {'/ floor':>7s}"
          "  load  kernels")  # fmt: skip
    floor = None
    for name in (FLOOR, *args.methods):
        run_child(name, args.params)  # numba's cache warm
        figures, load = run_child(name, args.params)
        (numba_s, first_s, second_s), kernels = figures["spent"], figures["kernels"]
        floor = floor or first_s[0]
        print(
            f"{name:16s} {numba_s[0]:6.3f}/{numba_s[1]:6.3f} {first_s[0]:6.3f}/{first_s[1]:6.3f} "
            f"{second_s[0]:6.3f}/{second_s[1]:6.3f} {first_s[0] / floor:7.2f}  {load:.2f}  "
            + ", ".join(m.rpartition(".")[2] for m in kernels)
        )


if __name__ == "__main__":
    main()
