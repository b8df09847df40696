"""klt-sector in the engine: route views and how many tracking steps a job takes.

With ``route_shape: tree`` every route of a goal extends a shorter one, so a home job tracks the
goal's corners once per current position (the tracker's cache holds each route prefix); with
``line`` the straight routes share fewer prefixes. Route views are described without corners.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import arena_config

from homebench.config import RunConfig
from homebench.evaluation.jobs import read_result, run_describe_job, run_home_job
from homebench.evaluation.plan import make_plan
from homebench.evaluation.sources import prepare_sources
from homebench.methods.klt_tracking import KltTracker


def _run(folder: Path, manifest: Path, shape: str, monkeypatch: pytest.MonkeyPatch) -> dict:
    """Describe and home jobs of one goal in this process; the tracking steps and corner
    detections of the home job, and its pairs' AE."""
    entry = {"method": "klt-sector", "params": {"route_shape": shape}}
    config = RunConfig.model_validate(
        arena_config(folder, manifest, goals=[[0, 0]], methods=[entry])
    )
    plan = make_plan(config, prepare_sources(config, 1), folder / "config.yaml")
    run_dir = folder / "run"
    for job in plan.describe:
        assert run_describe_job(job, run_dir).error is None
    counts = {"step": 0, "detect": 0}
    for name in counts:
        original = getattr(KltTracker, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            counts[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(KltTracker, name, counted)
    (job,) = plan.home
    assert run_home_job(job, run_dir).error is None
    monkeypatch.undo()
    rows = read_result(job.result_path(run_dir), job.key)["rows"]
    return {**counts, "currents": len(job.currents), "ae": [row["ae"] for row in rows]}


def test_a_tree_of_routes_tracks_once_per_current(tmp_path, arena_manifest, monkeypatch):
    tree = _run(tmp_path / "tree", arena_manifest, "tree", monkeypatch)
    line = _run(tmp_path / "line", arena_manifest, "line", monkeypatch)
    assert tree["step"] == tree["currents"]
    assert line["step"] > tree["step"]
    # route views are read for their images: no corners detected in a home job
    assert tree["detect"] == line["detect"] == 0
    assert None not in tree["ae"] and None not in line["ae"]
