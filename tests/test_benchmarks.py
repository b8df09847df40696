"""The benchmark scripts still run. They are run by hand, so nothing else notices when one
breaks (``bench_route.py`` failed at its defaults for several stops: its own tracker settings
predated the camera model). Each runs with its smallest arguments as a user would, from the
repository root, exits 0 and prints what the timing rule asks: process CPU and wall time, a
floor measured in the same process, the load average. Slow: a few minutes in all."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Each script and its smallest arguments.
SCRIPTS = {
    "bench_baselines.py": ["--widths", "144", "--repeats", "1"],
    "bench_block_matching.py": ["--pairs", "2"],
    "bench_config.py": ["configs/quickstart.yaml", "--jobs", "2", "--no-report"],
    "bench_first_call.py": ["--methods", "block-matching"],
    "bench_generate.py": ["--grid", "2", "3"],
    "bench_isolation.py": ["--calls", "20"],
    "bench_klt.py": ["--repeats", "1", "--steps", "3"],
    "bench_min_warping.py": ["--rounds", "1", "--pairs", "4"],
    "bench_render.py": ["--poses", "1"],
    "bench_route.py": ["--length", "0.5"],
    "bench_run.py": ["--goals", "1", "--methods", "warping"],
    "bench_sift.py": ["--repeats", "1"],
    "bench_sweep.py": ["--goals", "1"],
    "bench_threads.py": ["--rounds", "1", "--pairs", "2", "--methods", "warping", "did"],
    "bench_warping.py": ["--repeats", "1"],
    "bench_warping_2d.py": ["--rounds", "1", "--pairs", "4"],
}
#: Timed hand-overs between processes: wall time per call against the in-process loop, as a
#: worker's CPU for one hand-over is not separable from the pool's.
HAND_OVER = {"bench_isolation.py"}


def test_every_benchmark_script_is_listed() -> None:
    assert sorted(SCRIPTS) == sorted(p.name for p in (ROOT / "benchmarks").glob("bench_*.py"))


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_benchmark_runs_and_reports_cpu_wall_floor_and_load(script: str) -> None:
    result = subprocess.run(
        [sys.executable, f"benchmarks/{script}", *SCRIPTS[script]],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout.lower()
    assert "load" in out
    if script not in HAND_OVER:
        assert "cpu" in out and "wall" in out and "floor" in out, result.stdout
