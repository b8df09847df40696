"""Faults during a run: a failing job, a full disk. The run reports them and loses nothing."""

from __future__ import annotations

import errno
import json
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from conftest import run_config

from homebench.errors import DataError
from homebench.fileio import write_text_atomic
from homebench.methods.base import HomingEstimate, View
from homebench.methods.registry import register


@register
@dataclass(frozen=True)
class Fragile:
    """Test method: home direction from the mean column brightness; raises for one goal."""

    name: ClassVar[str] = "fragile"
    image_kind: ClassVar[str] = "unfolded"
    bad_mean: float = -1.0

    def describe(self, view: View) -> float:
        return float(np.mean(view.image))

    def home(self, current: float, goal: float) -> HomingEstimate:
        if goal == self.bad_mean:
            raise RuntimeError("simulated failure in home")
        return HomingEstimate(angle=0.0)


def _config(tmp_path: Path, manifest: Path, bad_mean: float) -> dict:
    return {
        "output": str(tmp_path / "run"),
        "databases": {"arena": str(manifest)},
        "conditions": ["arena-arena"],
        "goals": [[0, 0], [1, 1], [2, 2]],
        "methods": [{"method": "fragile", "params": {"bad_mean": bad_mean}}],
        "jobs": 1,
    }


def test_a_failing_job_is_reported_and_the_others_finish(
    tmp_path: Path, arena_manifest: Path
) -> None:
    from homebench.data.catalog import resolve

    goal_mean = float(np.mean(resolve(str(arena_manifest)).image(1, 1, "unfolded")))
    result = run_config(tmp_path, _config(tmp_path, arena_manifest, goal_mean))
    assert result.exit_code == 1
    assert "failed: RuntimeError: simulated failure in home" in result.stderr
    assert len(list((tmp_path / "run" / "jobs").glob("*.json"))) == 2
    assert "1 job(s) of the plan have no result here yet" in result.stdout


def test_disk_full_names_the_path_and_leaves_no_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "result.json"

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("homebench.fileio.os.fsync", full)
    with pytest.raises(DataError, match=r"result\.json: cannot write \(No space left on device\)"):
        write_text_atomic(target, json.dumps({"a": 1}))
    assert list(tmp_path.iterdir()) == []
