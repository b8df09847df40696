"""A home job's result file: one row per current view, in the columns' order, against the
arena's ground truth; a pair that fails, or has no estimate, or answers NaN, keeps its row,
and the file is strict JSON (no NaN tokens) that other tools can read."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import arena_config, run_config
from plugins import install_plugin

from homebench.config import RunConfig
from homebench.evaluation import pair_calls
from homebench.evaluation.jobs import ROW_COLUMNS, run_describe_job, run_home_job
from homebench.evaluation.plan import make_plan
from homebench.evaluation.sources import load_view, open_source, prepare_sources
from homebench.geometry import angle_diff
from homebench.methods.base import HomingEstimate
from homebench.methods.warping.method import Warping

ANGLE = 0.25  # the stub's answer in the current robot frame (radians)


def _refuse_constant(name: str) -> float:
    raise ValueError(f"not strict JSON: {name}")


@pytest.mark.parametrize("calls", ["pair by pair", "batch"])
def test_rows_hold_each_pairs_answer_and_truth_and_the_file_is_strict_json(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch, calls: str
) -> None:
    """The same rows whether the method homes pair by pair or in a batch call; a batch that
    raises is made again pair by pair, so only its failing pair fails."""
    config = RunConfig.model_validate(
        arena_config(tmp_path, arena_manifest, goals=[[1, 2]], methods=[{"method": "warping"}])
    )
    plan = make_plan(config, prepare_sources(config, 1), tmp_path / "config.yaml")
    run_dir = tmp_path / "run"
    for job in plan.describe:
        assert run_describe_job(job, run_dir).error is None
    (job,) = plan.home
    currents = [(task.i, task.j) for task in job.currents]
    undecided, nan_score, failing = currents[0], currents[1], currents[2]
    views = {  # the current views by their features (warping's signals differ from view to view)
        Warping().describe(load_view(t.source, t.i, t.j, "unfolded")).tobytes(): (t.i, t.j)
        for t in job.currents
    }
    batches = []

    def stub(self, current, goal, **extra):
        here = views[current.tobytes()]
        if here == failing:
            raise RuntimeError("stub failure")
        if here == undecided:
            return HomingEstimate.none(n_landmarks=2)
        score = math.nan if here == nan_score else np.float32(0.5)
        return HomingEstimate(ANGLE, rotation=np.float64(0.125), n_landmarks=7, score=score)

    def stub_many(self, currents, goal, **extra):
        batches.append(len(currents))
        if any(views[c.tobytes()] == failing for c in currents):
            raise RuntimeError("a batch with the failing pair")
        return [stub(self, c, goal) for c in currents]

    monkeypatch.setattr(Warping, "home", stub)
    monkeypatch.setattr(pair_calls, "_CALLED", set())  # as in a fresh worker
    if calls == "batch":
        monkeypatch.setattr(Warping, "home_many", stub_many)
    else:
        monkeypatch.delattr(Warping, "home_many")
    assert run_home_job(job, run_dir).error is None
    # the first pair alone (a process's first call), then one batch, which fails
    assert batches == ([len(currents) - 1] if calls == "batch" else [])

    text = job.result_path(run_dir).read_text(encoding="utf-8")
    rows = json.loads(text, parse_constant=_refuse_constant)["rows"]
    assert [(row["current_i"], row["current_j"]) for row in rows] == currents
    assert all(list(row) == list(ROW_COLUMNS) for row in rows)
    database = open_source(job.goal.source)
    goal_xy = database.grid.position(job.goal.i, job.goal.j)
    for row in rows:
        here = (row["current_i"], row["current_j"])
        offset = goal_xy - database.grid.position(*here)
        truth = math.atan2(offset[1], offset[0]) - database.heading(*here)
        assert float(angle_diff(row["truth"], truth)) == pytest.approx(0.0, abs=1e-12)
        assert row["distance_m"] == pytest.approx(math.hypot(*offset), abs=1e-12)
        assert row["heading"] == pytest.approx(database.heading(*here), abs=1e-12)
        if here == failing:
            assert "stub failure" in row["error"]
            assert row["estimate"] is row["ae"] is row["home_ms"] is None
            continue
        assert row["error"] is None  # a process's first home has no time (see timed)
        assert row["home_ms"] is None or row["home_ms"] >= 0.0
        if here == undecided:
            assert row["estimate"] is row["ae"] is row["estimate_world"] is None
            assert row["n_landmarks"] == 2
            continue
        assert row["estimate"] == ANGLE and row["rotation_estimate"] == 0.125
        assert row["estimate_world"] == pytest.approx(row["heading"] + ANGLE, abs=1e-12)
        assert row["ae"] == pytest.approx(abs(float(angle_diff(ANGLE, row["truth"]))), abs=1e-9)
        assert row["n_landmarks"] == 7
        assert row["score"] == (None if here == nan_score else 0.5)


def test_a_parameter_beyond_64_bits_is_written_exactly(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """orjson writes no integer beyond 64 bits; such a result file is written by the stdlib."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch)
    entry = {"method": plugin.method, "params": {"raise_goal": 2**70}}
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, methods=[entry]))
    assert result.exit_code == 0, result.output
    records = [json.loads(p.read_text()) for p in (tmp_path / "run" / "jobs").glob("*.json")]
    assert records and all(record["params"] == {"raise_goal": 2**70} for record in records)
    assert all(row["error"] is None for record in records for row in record["rows"])


#: A method whose first describe and home in a process take 0.4 s more (a kernel compiling).
SLOW_FIRST = '''
"""A method with a one-off cost at its first calls in a process."""

import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homebench.methods.base import HomingEstimate

_CALLED = set()


def _first(kind):
    if kind not in _CALLED:
        _CALLED.add(kind)
        time.sleep(0.4)


@dataclass(frozen=True)
class Faulty:
    """Test method: slow at its first describe and home in a process."""

    name: ClassVar[str] = "{name}"
    image_kind: ClassVar[str] = "unfolded"

    def describe(self, view):
        _first("describe")
        return float(np.mean(view.image))

    def home(self, current, goal):
        _first("home")
        return HomingEstimate(angle=0.1, n_landmarks=1)
'''


def test_times_are_the_steady_cost_without_a_first_calls_compilation(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """min-warping's numba kernels compiled inside the first timed call: the quick start's
    summary showed 366 ms per pair against 14 ms in the next condition."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, SLOW_FIRST)
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": plugin.method}])
    result = run_config(tmp_path, config, "--jobs", "1")
    assert result.exit_code == 0, result.output
    rows = [row for job in (tmp_path / "run" / "jobs").iterdir()
            for row in json.loads(job.read_text())["rows"]]  # fmt: skip
    times = np.array(
        [[r[k] for k in ("home_ms", "describe_ms", "goal_describe_ms")] for r in rows], float
    )
    assert np.nanmax(times) < 200  # the first call of each has no time: it holds one-off costs
    assert np.isnan(times[:, 0]).sum() == 1
