"""A whole config end to end: CPU and wall of ``homebench run`` at --jobs 1 and 2, and each
method's share of it.

    python benchmarks/bench_config.py                          # configs/baselines.yaml
    python benchmarks/bench_config.py configs/quickstart.yaml --jobs 2 --no-report

Each run is a fresh ``homebench run CONFIG output=TMP --jobs N`` in a subprocess (its PDF
report included unless ``--no-report``), after the config's worlds were generated (not timed).
Printed per run: wall seconds, the CPU seconds of the command and of every process it started
(user + system, as they are waited for), and the 1-minute load average before and after. Then
per method, from the first run's pairs: its pairs and failed pairs, its calls' time (the
describe and home times its jobs' workers recorded: wall ms of each call inside a one-thread
worker, its CPU on an idle host, more on a busy one; each image counted once; a process's first
call of each kind, which holds one-off costs, is not timed) and its share of all methods'
calls; their sum is the run's floor.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from timing import cpu_with_children, machine_cpu_s, others_cores, speedup

from homebench import api
from homebench.config import load_config
from homebench.evaluation.sources import prepare_sources


def timed_run(config: Path, output: Path, jobs: int, report: bool) -> tuple[float, float, float]:
    """Wall and CPU seconds (this process's children) of one fresh ``homebench run``, and the
    cores other processes kept busy meanwhile."""
    command = [sys.executable, "-m", "homebench", "run", str(config), f"output={output}"]
    command += ["--jobs", str(jobs), "--no-progress"] + ([] if report else ["--no-report"])
    machine, wall, cpu = machine_cpu_s(), time.perf_counter(), cpu_with_children()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    wall, cpu = time.perf_counter() - wall, cpu_with_children() - cpu
    return wall, cpu, others_cores(wall, cpu, machine)


def method_seconds(pairs: pd.DataFrame) -> pd.DataFrame:
    """Per method of a run's pair table: its pairs, failed pairs and the seconds of its describe
    and home calls: every pair's home, every current image's describe once (the conditions
    share their current views) and every goal's once."""
    ms = pairs.assign(
        **{c: pd.to_numeric(pairs[c]) for c in ("home_ms", "describe_ms", "goal_describe_ms")}
    )
    place = ["style", "method", "current_database", "current_i", "current_j", "rotation"]
    currents = ms.drop_duplicates(place)
    goals = ms.drop_duplicates(["style", "method", "goal_database", "goal_i", "goal_j"])
    spent = (
        ms.groupby("method")["home_ms"].sum()
        + currents.groupby("method")["describe_ms"].sum()
        + goals.groupby("method")["goal_describe_ms"].sum()
    )
    return pd.DataFrame(
        {
            "pairs": ms.groupby("method").size(),
            "failed": ms["error"].notna().groupby(ms["method"]).sum(),
            "seconds": spent / 1e3,
        }
    ).sort_values("seconds", ascending=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", nargs="?", type=Path, default=Path("configs/baselines.yaml"))
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--no-report", action="store_true")
    args = parser.parse_args()
    prepare_sources(load_config(args.config), 2)  # the worlds, generated once, not timed
    cpu_of_run: dict[int, float] = {}
    walls: dict[int, float] = {}
    with tempfile.TemporaryDirectory() as scratch:
        for jobs in args.jobs:
            before = os.getloadavg()[0]
            output = Path(scratch) / f"jobs{jobs}"
            wall, cpu, others = timed_run(args.config, output, jobs, not args.no_report)
            cpu_of_run[jobs], walls[jobs] = cpu, wall
            print(f"--jobs {jobs}: wall {wall:.1f} s, CPU {cpu:.1f} s, "
                  f"load {before:.2f} -> {os.getloadavg()[0]:.2f}", flush=True)  # fmt: skip
            if jobs > 1 and 1 in walls:
                print(f"  speed-up over --jobs 1: {speedup(walls[1], wall, jobs, others)}")
        first = args.jobs[0]
        methods = method_seconds(api.tables(Path(scratch) / f"jobs{first}").pairs)
    calls = methods["seconds"].sum()
    print(f"floor: the methods' calls in the --jobs {first} run, {calls:.1f} s (the run's CPU: "
          f"{cpu_of_run[first]:.1f} s, {cpu_of_run[first] / calls:.2f} x)")  # fmt: skip
    print(f"{'method':16s} {'pairs':>6s} {'failed':>6s} {'calls s':>8s} {'share':>6s}")
    for method, row in methods.iterrows():
        print(f"{method:16s} {int(row.pairs):6d} {int(row.failed):6d} {row.seconds:8.1f} "
              f"{row.seconds / calls:6.1%}")  # fmt: skip


if __name__ == "__main__":
    main()
