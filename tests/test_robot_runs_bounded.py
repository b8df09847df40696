"""Robot runs (route, closed loop) as safe as grid runs: a trial that hangs past the timeout
fails alone and the run goes on; every size a route or a start set implies is bounded before
anything is allocated, one line naming the key, exit 2; a trial file that does not fit its
schema is a missing result to the report and computed again by a run.

The runs are real processes (``python -m homebench run``), as a user starts them, on tiny
generated worlds; the hanging method is a plugin whose ``home`` sleeps for an hour.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from conftest import homebench_limited
from plugins import install_plugin
from test_closed_loop_run import TINY
from test_route_experiment import SMALL_WORLD

from homebench.cli import main

#: A method that answers no estimate, or hangs in ``home`` when told to.
HANGING = '''
"""A homing method that hangs on request (homebench's tests)."""

import time
from dataclasses import dataclass
from typing import ClassVar

from homebench.methods.base import HomingEstimate


@dataclass(frozen=True)
class Faulty:
    """Test method: no estimate, or a hang of an hour with ``hang``."""

    name: ClassVar[str] = "{name}"
    image_kind: ClassVar[str] = "unfolded"
    hang: bool = False

    def describe(self, view):
        return 0.0

    def home(self, current, goal):
        if self.hang:
            time.sleep(3600)
        return HomingEstimate.none()
'''
#: Long enough for the quick trial of a loaded 2-core host (it took over 3 s at load 10), short
#: enough to keep the test's wait small.
TIMEOUT_S = 10
#: A short route: 4 frames out, one snapshot (home).
ROUTE = {
    "kind": "route",
    "name": "hang",
    "world": SMALL_WORLD,
    "routes": [{"name": "line", "waypoints": [[2.0, 2.5], [2.0, 2.8]]}],
    "motion": {"step_length": 0.1, "max_turn_deg": 20},
    "pairwise": {"max_leg_steps": 3},
}


def _run(tmp_path: Path, config: dict, *options: str) -> tuple[subprocess.CompletedProcess, float]:
    """`homebench run` of ``config`` in its own process; the result and its wall time (s)."""
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump({**config, "output": str(tmp_path / "run")}))
    command = [sys.executable, "-m", "homebench", "run", str(path), "--no-progress", "--no-report"]
    start = time.monotonic()
    done = subprocess.run([*command, *options], capture_output=True, text=True, timeout=240)
    return done, time.monotonic() - start


def _timed_out(done: subprocess.CompletedProcess) -> list[str]:
    """The stderr lines of trials that failed by the timeout."""
    lines = done.stderr.splitlines()
    return [line for line in lines if f"failed: timed out after {TIMEOUT_S} s" in line]


def test_a_route_trial_that_hangs_times_out_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--timeout`` as for a grid run: the hanging method's trial fails, the other's is kept."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, HANGING)
    methods = [
        {"method": plugin.method, "label": "hangs", "params": {"hang": True}},
        {"method": plugin.method, "label": "quick"},
    ]
    done, took = _run(tmp_path, {**ROUTE, "methods": methods}, "--timeout", str(TIMEOUT_S))
    assert done.returncode == 1, done.stderr
    assert took < TIMEOUT_S + 60, "the run must end soon after the timeout"
    assert len(_timed_out(done)) == 1, done.stderr
    table = pd.read_csv(tmp_path / "run" / "tables" / "routes.csv")
    assert list(table["method"]) == ["quick"]
    assert "1 trial(s) computed, 0 reused, 1 failed" in done.stdout
    resolved = yaml.safe_load((tmp_path / "run" / "config.resolved.json").read_text())
    assert resolved["job_timeout_s"] == TIMEOUT_S  # what the run used


def test_a_closed_loop_trial_that_hangs_times_out_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``job_timeout_s`` in the config, as in a grid config."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, HANGING)
    config = {
        **TINY,
        "methods": [{"method": plugin.method, "params": {"hang": True}}],
        "controls": ["truth"],
        "starts": {"spacing": 0.6, "region": [0.0, 0.0, 0.1, 0.1]},  # one start
        "job_timeout_s": TIMEOUT_S,
    }
    done, took = _run(tmp_path, config, "--jobs", "2")
    assert done.returncode == 1, done.stderr
    assert took < TIMEOUT_S + 60, "the run must end soon after the timeout"
    assert len(_timed_out(done)) == 1, done.stderr
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv")
    assert list(summary["method"]) == ["truth"]


@pytest.mark.parametrize(
    ("config", "override", "key"),
    [
        # a far waypoint: 7.45 GiB allocated to check the route at 1 cm
        (ROUTE, "routes.0.waypoints=[[0.05, 0], [1e7, 0]]", "routes[0].waypoints: "),
        # the route's length overflows a resampling
        (ROUTE, "routes.0.waypoints=[[1e300, 0], [1, 1]]", "routes[0].waypoints: "),
        # long steps keep the frames few; the check at 1 cm stops at the room's wall
        (
            {**ROUTE, "motion": {"step_length": 1e6}},
            "routes.0.waypoints=[[2.0, 2.5], [1e9, 2.5]]",
            "routes[0] (line): ",
        ),
        # turns of 1e-9 deg per frame
        (ROUTE, "motion.max_turn_deg=1e-9", "routes[0].waypoints: "),
        (ROUTE, "routes.0.repeats=800000", "routes[0].repeats: "),  # 12,000,000 frames in all
        (TINY, "motion.max_steps=1000000000", "motion.max_steps: "),
        (TINY, "training={routes: 1000000, length_m: 1.5, spacing_m: 0.1}", "training: "),
        (TINY, "starts={spacing: 0.1, region: [-1e308, 0, 1e308, 1]}", "starts."),
        (TINY, "starts={random: 10, region: [-1e308, 0, 1e308, 1]}", "starts."),
    ],
)
def test_every_size_a_route_or_start_set_implies_is_bounded(
    tmp_path: Path, config: dict, override: str, key: str
) -> None:
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump({**config, "output": str(tmp_path / "run")}))
    start = time.monotonic()
    done = homebench_limited("run", str(path), override, "--no-progress")
    assert time.monotonic() - start < 30
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("homebench: error: "), done.stderr
    assert key in lines[0], lines[0]
    assert not (tmp_path / "run").exists()


def _damaged_run(
    tmp_path: Path, config: dict, pattern: str, damage: list[tuple[str, object]]
) -> list[tuple[Path, str]]:
    """Run ``config`` (in this process), then give the k-th trial file matching ``pattern``
    the k-th ``(field, value)`` of ``damage`` (of its summary, or of the record for
    ``trajectory`` and ``outbound``); each damaged file with its field."""
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump({**config, "output": str(tmp_path / "run")}))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert result.exit_code == 0, result.output
    victims = sorted((tmp_path / "run").glob(pattern))[: len(damage)]
    assert len(victims) == len(damage)
    for victim, (field, value) in zip(victims, damage, strict=True):
        record = json.loads(victim.read_text())
        part = record if field in ("trajectory", "outbound") else record["summary"]
        part[field] = value
        victim.write_text(json.dumps(record))
    return [(victim, field) for victim, (field, _) in zip(victims, damage, strict=True)]


def _read_as_missing_and_recomputed(
    tmp_path: Path, damaged: list[tuple[Path, str]], total: int
) -> None:
    """The report warns of each damaged file as a missing result naming its field; a rerun
    computes exactly those trials again."""
    run = tmp_path / "run"
    report = CliRunner().invoke(main, ["report", str(run), "--format", "md", "--no-progress"])
    assert report.exit_code == 0, report.output
    lines = report.stderr.splitlines()
    assert len(lines) == len(damaged), report.stderr
    for victim, field in damaged:
        name = victim.relative_to(run).as_posix()
        (line,) = [line for line in lines if f"missing job result {name} (" in line]
        assert line.startswith("homebench: warning: "), line
        where = "" if field in ("trajectory", "outbound") else "summary."
        assert f": corrupt, {where}{field}" in line, line
    again = CliRunner().invoke(main, ["run", str(tmp_path / "config.yaml"), "--no-progress",
                                      "--no-report"])  # fmt: skip
    n = len(damaged)
    assert f"{n} trial(s) computed, {total - n} reused" in again.stdout, again.output


def test_closed_loop_trial_files_that_do_not_fit_are_missing_and_recomputed(
    tmp_path: Path,
) -> None:
    """Each of these crashed the report (and the tables of a rerun); one damaged file each."""
    config = {**TINY, "methods": [], "controls": ["truth", "random"]}  # 24 trials, no views
    damage = [
        ("success", "yes"),
        ("steps", [1]),
        ("outcome", 5),
        ("style", "lab"),
        ("trajectory", [["a", 1, 2]]),
    ]
    damaged = _damaged_run(tmp_path, config, "trials/*/truth/*.json", damage)
    _read_as_missing_and_recomputed(tmp_path, damaged, 24)


def test_route_trial_files_that_do_not_fit_are_missing_and_recomputed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, HANGING)
    routes = [{**ROUTE["routes"][0], "repeats": 4}]
    config = {**ROUTE, "routes": routes, "methods": [{"method": plugin.method}]}
    damage = [("visual_error_m", "far"), ("length_m", "x"), ("outbound", 5)]
    damaged = _damaged_run(tmp_path, config, "routes/*.json", damage)
    _read_as_missing_and_recomputed(tmp_path, damaged, 4)


@pytest.mark.parametrize("kind", ["route", "closed-loop"])
def test_a_robot_run_into_another_runs_folder_is_refused_and_leaves_it_alone(
    tmp_path: Path, kind: str
) -> None:
    """A robot run wrote its config.resolved.json over whatever run its output folder held (a
    grid run's included), and two runs into one folder ran at once. Now the folder belongs to
    one config (another is refused unless --force) and is locked while a run uses it."""
    from homebench.evaluation.run_folder import lock_run_folder

    grid_run = tmp_path / "grid-run"
    grid_run.mkdir()
    held = json.dumps({"name": "a grid run", "output": str(grid_run), "methods": []})
    (grid_run / "config.resolved.json").write_text(held)
    base = TINY if kind == "closed-loop" else {
        "kind": "route", "name": "r", "world": SMALL_WORLD, "methods": [{"method": "warping"}],
        "routes": [{"name": "ell", "waypoints": [[2.0, 2.5], [2.0, 3.6]]}],
    }  # fmt: skip
    path = tmp_path / "robot.yaml"
    path.write_text(yaml.safe_dump({**base, "output": str(grid_run)}))
    refused = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert refused.exit_code == 2, refused.output
    assert "holds the run of another config" in refused.output and "--update" not in refused.output
    assert (grid_run / "config.resolved.json").read_text() == held
    written = {p.name for p in grid_run.iterdir()} - {".homebench.lock", ".homebench.claim"}
    assert written == {"config.resolved.json"}  # its locks aside, as a refused grid run leaves

    path.write_text(yaml.safe_dump({**base, "output": str(tmp_path / "busy")}))
    with lock_run_folder(tmp_path / "busy"):
        busy = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert busy.exit_code == 2 and "in use by another homebench run" in busy.output
