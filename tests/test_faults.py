"""Faults during a run: methods that raise, segfault, hang or exhaust memory, a full disk.

A failing job is a failed *job*, never a failed run: the run ends in bounded time, every other
job's result is saved, the failures are listed with their causes and recorded in the run folder,
and only ``--retry-failed`` runs them again.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import arena_config, run_config
from mounts import tmpfs
from plugins import Plugin, install_plugin

from homebench.errors import DataError
from homebench.fileio import write_text_atomic

GOALS = [(0, 0), (1, 1), (2, 2), (3, 3), (0, 4), (3, 0)]
#: The jobs' timeout: long enough that no job but the hanging one reaches it on 2 cores shared
#: by the test workers and a Dask cluster's (4 s did not always suffice there), short enough to
#: keep the test quick.
TIMEOUT_S = 10


@pytest.fixture
def plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Plugin:
    return install_plugin(tmp_path / "plugin", monkeypatch)


def _mean(manifest: Path, i: int, j: int) -> float:
    """The fault plugin's features of the arena image at (i, j): its mean grey level."""
    from homebench.data.catalog import resolve

    return float(np.mean(resolve(str(manifest)).image(i, j, "unfolded")))


def _config(tmp_path: Path, manifest: Path, plugin: Plugin, goals=GOALS, **faults: float) -> dict:
    """The fault plugin with ``faults`` beside a fast warping entry (which never fails)."""
    return {
        "output": str(tmp_path / "run"),
        "databases": {"arena": str(manifest)},
        "conditions": ["arena-arena"],
        "goals": [list(goal) for goal in goals],
        "methods": [
            {"method": plugin.method, "label": "faulty", "params": faults},
            {"method": "warping", "params": {"n_rho": 4, "n_alpha": 24, "n_psi": 24}},
        ],
        "job_timeout_s": TIMEOUT_S,
        "worker_memory_mb": 1024,  # a worker needs ~700 MB of address space
    }


def _run(tmp_path: Path, config: dict, *options: str) -> subprocess.CompletedProcess:
    """`homebench run` in its own process, as a user runs it (a crash there cannot hit pytest)."""
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    command = [sys.executable, "-m", "homebench", "run", str(path), "--no-progress", "--no-report"]
    return subprocess.run(
        [*command, *options], capture_output=True, text=True, timeout=240, check=False
    )


def _failures(run_dir: Path) -> dict[str, dict]:
    return {
        record["key"]: record
        for record in (json.loads(p.read_text()) for p in (run_dir / "failures").glob("*.json"))
    }


@pytest.mark.parametrize(
    "options",
    [
        pytest.param(("--jobs", "1"), marks=pytest.mark.slow),  # CI time: --jobs 2 is one pool
        ("--jobs", "2"),
        # CI time: test_run checks Dask's tables; its isolation is the local pool's code
        pytest.param(("--backend", "dask", "--jobs", "2"), marks=pytest.mark.slow),
    ],
    ids=["jobs1", "jobs2", "dask"],
)
def test_crashing_hanging_raising_and_exhausting_methods_fail_alone(
    tmp_path: Path, arena_manifest: Path, plugin: Plugin, options: tuple[str, ...]
) -> None:
    """A crash or a hang fails its job; an exception or a MemoryError fails its pair."""
    faults = {
        "raise_goal": _mean(arena_manifest, 1, 1),
        "segfault_goal": _mean(arena_manifest, 2, 2),
        "hang_goal": _mean(arena_manifest, 3, 3),
        "oom_pair": [_mean(arena_manifest, 0, 4), _mean(arena_manifest, 1, 2)],
    }
    start = time.monotonic()
    result = _run(tmp_path, _config(tmp_path, arena_manifest, plugin, **faults), *options)
    assert time.monotonic() - start < 150, "the run must end in bounded time"
    assert result.returncode == 1, result.stderr
    run_dir = tmp_path / "run"
    assert len(list((run_dir / "jobs").glob("*.json"))) == 2 * len(GOALS) - 2
    assert f"{2 * len(GOALS) - 2} job(s) computed, 0 reused, 2 failed" in result.stdout
    assert "other shards" not in result.stdout
    lines = result.stderr.splitlines()
    for goal, cause in [
        ((2, 2), "failed: worker killed by SIGSEGV"),
        ((3, 3), f"failed: timed out after {TIMEOUT_S} s"),
        ((1, 1), "19 pair(s) failed: RuntimeError: simulated failure in home"),
        ((0, 4), "1 pair(s) failed: out of memory (MemoryError"),
    ]:
        assert sum(f"goal {goal}" in line and cause in line for line in lines) == 1, (cause, lines)
    assert sorted(record["job"] for record in _failures(run_dir).values()) == [
        "faulty, arena-arena, goal (2, 2)",
        "faulty, arena-arena, goal (3, 3)",
    ]
    pairs = pd.read_csv(run_dir / "tables" / "pairs.csv")
    faulty = pairs[pairs["method"] == "faulty"]
    assert len(faulty) == 4 * 19 and faulty["error"].notna().sum() == 20
    assert len(pairs[pairs["method"] == "warping"]) == len(GOALS) * 19


def test_failed_jobs_are_retried_only_on_request(
    tmp_path: Path, arena_manifest: Path, plugin: Plugin
) -> None:
    faults = {
        "raise_goal": _mean(arena_manifest, 1, 1),
        "segfault_goal": _mean(arena_manifest, 2, 2),
    }
    config = _config(tmp_path, arena_manifest, plugin, goals=GOALS[:3], **faults)
    assert _run(tmp_path, config, "--jobs", "2").returncode == 1
    run_dir = tmp_path / "run"
    finished = {p: p.stat().st_mtime_ns for p in (run_dir / "jobs").glob("*.json")}
    assert len(finished) == 5
    result = _run(tmp_path, config, "--jobs", "2")
    assert result.returncode == 1
    assert "0 job(s) computed, 5 reused, 1 failed" in result.stdout
    assert "--retry-failed" in result.stderr
    (failure,) = _failures(run_dir).values()
    assert failure["attempts"] == 1
    result = _run(tmp_path, config, "--jobs", "2", "--retry-failed")
    assert result.returncode == 1
    # the crashed job and the job with failed pairs ran again, and only they
    assert "1 job(s) computed, 4 reused, 1 failed" in result.stdout
    assert "failed (attempt 2): worker killed by SIGSEGV" in result.stderr
    (failure,) = _failures(run_dir).values()
    assert failure["attempts"] == 2
    now = {p: p.stat().st_mtime_ns for p in (run_dir / "jobs").glob("*.json")}
    assert sum(now[p] != finished[p] for p in finished) == 1


def test_a_failing_pair_keeps_the_other_rows_of_its_job(
    tmp_path: Path, arena_manifest: Path, plugin: Plugin
) -> None:
    faults = {"raise_current": _mean(arena_manifest, 3, 4)}
    result = run_config(tmp_path, _config(tmp_path, arena_manifest, plugin, GOALS[1:3], **faults))
    assert result.exit_code == 1, result.output
    assert "1 pair(s) failed: ValueError: simulated failure of one pair" in result.stderr
    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    faulty = pairs[pairs["method"] == "faulty"]
    assert len(faulty) == 2 * 19
    broken = faulty[faulty["error"].notna()]
    assert list(zip(broken["current_i"], broken["current_j"], strict=True)) == [(3, 4), (3, 4)]
    assert (broken["error"] == "ValueError: simulated failure of one pair").all()
    assert broken["estimate_rad"].isna().all()
    assert faulty.loc[faulty["error"].isna(), "estimate_rad"].notna().all()
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv").set_index("method")
    assert summary.loc["faulty", "n_failed"] == 2
    assert summary.loc["faulty", "pairs"] == 2 * 18
    assert summary.loc["faulty", "no_estimate_share"] == 0
    assert summary.loc["warping", "n_failed"] == 0


def test_the_summary_counts_a_failed_job_as_failed(
    tmp_path: Path, arena_manifest: Path, plugin: Plugin
) -> None:
    faults = {"segfault_goal": _mean(arena_manifest, 1, 1)}
    config = _config(tmp_path, arena_manifest, plugin, GOALS[:3], **faults)
    result = run_config(tmp_path, config, "--jobs", "1")  # in this process: a crash stays out
    assert result.exit_code == 1
    assert "5 job(s) computed, 0 reused, 1 failed" in result.stdout
    assert "other shards" not in result.stdout
    assert "(faulty, arena-arena, goal (1, 1)) failed: worker killed by SIGSEGV" in result.stderr
    assert len(list((tmp_path / "run" / "jobs").glob("*.json"))) == 5


PAGE = 4096


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A real 1 MB file system (tmpfs) at ``tmp_path / "disk"``; skips where none can be
    mounted (mounting needs root)."""
    folder = tmp_path / "disk"
    folder.mkdir()
    with tmpfs(folder, "size=1m") as problem:
        if problem:
            pytest.skip(problem)
        yield folder


def _fill(disk: Path, free_pages: int) -> Path:
    """Fill ``disk`` up to ``free_pages`` free pages of 4 KiB with one file; that file."""
    filler = disk / "filler"
    usage = os.statvfs(disk)
    filler.write_bytes(bytes(usage.f_bavail * usage.f_frsize - free_pages * PAGE))
    return filler


def test_a_full_disk_names_the_path_and_leaves_no_file(small_disk: Path) -> None:
    _fill(small_disk, 0)
    target = small_disk / "result.json"
    with pytest.raises(DataError, match=r"result\.json: cannot write \(No space left on device\)"):
        write_text_atomic(target, json.dumps({"a": "x" * 100_000}))
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler"]


@pytest.mark.parametrize(
    ("lost", "free_pages"), [(("features", "jobs"), 4), (("jobs",), 2)], ids=["describe", "home"]
)
def test_a_full_disk_stops_the_run_and_a_plain_rerun_recomputes(
    tmp_path: Path, arena_manifest: Path, small_disk: Path, lost: tuple[str, ...], free_pages: int
) -> None:
    """A run on a disk with room for its metadata only (a few pages of 4 KiB) stops with one
    line as it writes features (20 of a page each) or results (3 pages each), records no
    failure and no pair error, and once there is room a plain rerun (no --retry-failed)
    finishes."""
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": "warping"}])
    config["output"] = str(small_disk / "run")
    assert run_config(tmp_path, config).exit_code == 0
    run_dir = small_disk / "run"
    for folder in lost:
        shutil.rmtree(run_dir / folder)
    filler = _fill(small_disk, free_pages)
    result = run_config(tmp_path, config)
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"homebench: error: {run_dir / lost[0]}/")
    assert line.endswith("(No space left on device)")
    assert not list(run_dir.glob("failures/*"))
    for job in run_dir.glob("jobs/*.json"):
        assert not any(row["error"] for row in json.loads(job.read_text())["rows"])
    filler.unlink()
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    computed, reused = re.search(r"(\d+) job\(s\) computed, (\d+) reused", result.stdout).groups()
    assert int(computed) >= 1 and int(computed) + int(reused) == 2


#: A method whose answers are no estimates: ``home`` an infinite angle (``answer: inf``), or
#: ``home_many`` strings, one per pair (``answer: strings``); otherwise a fixed direction.
ODD_ANSWERS = '''
"""A homing method that answers what no method may (homebench's tests)."""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homebench.methods.base import HomingEstimate


@dataclass(frozen=True)
class Faulty:
    """Test method: odd answers."""

    name: ClassVar[str] = "{name}"
    image_kind: ClassVar[str] = "unfolded"
    answer: str = ""

    def describe(self, view):
        return float(np.mean(view.image))

    def home(self, current, goal):
        return HomingEstimate(angle=math.inf if self.answer == "inf" else 0.1)

    def home_many(self, currents, goal):
        if self.answer == "strings":
            return ["north"] * len(currents)
        return [self.home(current, goal) for current in currents]
'''


def _odd_run(tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch, answer: str):
    """A run of the odd-answers method (``answer``) on two goals; the result and its pairs."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, ODD_ANSWERS)
    config = _config(tmp_path, arena_manifest, plugin, GOALS[:2])
    config["methods"] = [{"method": plugin.method, "params": {"answer": answer}}]
    result = _run(tmp_path, config)
    return result, pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")


def test_an_infinite_angle_fails_its_pair_without_a_numpy_warning(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    result, pairs = _odd_run(tmp_path, arena_manifest, monkeypatch, "inf")
    assert result.returncode == 1, result.stderr
    assert "Warning" not in result.stderr, result.stderr
    message = "ValueError: home answered angle inf, not a finite number of radians"
    assert (pairs["error"] == message).all(), pairs["error"].unique()


def test_a_batch_of_strings_is_no_batch_of_estimates(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It was taken as the pairs' errors ("failed: north"); now the pairs are asked of
    ``home`` one by one."""
    result, pairs = _odd_run(tmp_path, arena_manifest, monkeypatch, "strings")
    assert result.returncode == 0, result.stderr
    assert pairs["error"].isna().all() and (pairs["estimate_rad"] == 0.1).all()


def _ignore_interrupts() -> None:
    """As a shell starts a background job (``homebench run ... &`` in a script)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.parametrize(
    "inherited",
    ["default", pytest.param("ignored", marks=pytest.mark.slow)],  # CI time: one by default
)
def test_ctrl_c_stops_a_run_at_once_and_a_rerun_resumes(
    tmp_path: Path, arena_manifest: Path, plugin: Plugin, inherited: str
) -> None:
    """kill -INT did not stop a run within 10 s (a run started with SIGINT ignored ran to its
    end). Now: within 2 s, one line saying how many jobs have results, exit 130; the rerun
    computes only the others."""
    config = _config(tmp_path, arena_manifest, plugin, hang_goal=_mean(arena_manifest, 3, 3))
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    command = [sys.executable, "-m", "homebench", "run", str(path), "--no-progress", "--no-report"]
    setup = _ignore_interrupts if inherited == "ignored" else None
    run = subprocess.Popen(
        [*command, "--jobs", "1"], stderr=subprocess.PIPE, text=True, preexec_fn=setup
    )
    jobs = tmp_path / "run" / "jobs"
    deadline = time.monotonic() + 120
    while len(list(jobs.glob("*.json"))) < 2 and time.monotonic() < deadline:
        time.sleep(0.1)
    run.send_signal(signal.SIGINT)
    start = time.monotonic()
    _, stderr = run.communicate(timeout=30)
    assert time.monotonic() - start < 2, "Ctrl-C must stop the run at once"
    assert run.returncode == 130, stderr
    (line,) = stderr.splitlines()
    total = 2 * len(GOALS)
    said = re.fullmatch(
        rf"homebench: interrupted: (\d+) of {total} job\(s\) have results in .*; rerun the "
        "same command to resume",
        line,
    )
    assert said, line
    done = len(list(jobs.glob("*.json")))  # and one the worker wrote as it was stopped
    assert int(said[1]) <= done <= int(said[1]) + 1, line
    again = _run(tmp_path, config)  # the hanging job times out
    assert f"{total - done - 1} job(s) computed, {done} reused, 1 failed" in again.stdout
