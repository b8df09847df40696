"""klt-sector in the engine: route views and how many tracking steps a job takes.

With ``route_shape: tree`` every route of a goal extends a shorter one, so a home job tracks the
goal's corners once per current position (the tracker's cache holds each route prefix); with
``line`` the straight routes share fewer prefixes. Route views are described without corners,
or read from the feature files of the job's current views.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import arena_config

from homebench.config import RunConfig
from homebench.evaluation import jobs
from homebench.evaluation.jobs import read_result, run_describe_job, run_home_job
from homebench.evaluation.plan import make_plan
from homebench.evaluation.sources import prepare_sources
from homebench.methods.klt_sector.tracking import KltTracker


def _run(
    folder: Path, manifest: Path, shape: str, monkeypatch: pytest.MonkeyPatch, stored: bool = True
) -> dict:
    """Describe and home jobs of one goal in this process; the tracking steps, corner
    detections and images read of the home job, and its pairs' AE. ``stored``: whether route
    views may come from the current views' feature files."""
    entry = {"method": "klt-sector", "params": {"route_shape": shape}}
    config = RunConfig.model_validate(
        arena_config(folder, manifest, goals=[[0, 0]], methods=[entry])
    )
    plan = make_plan(config, prepare_sources(config, 1), folder / "config.yaml")
    run_dir = folder / "run"
    for job in plan.describe:
        assert run_describe_job(job, run_dir).error is None
    counts = {"step": 0, "detect": 0, "load_view": 0}
    for owner, name in ((KltTracker, "step"), (KltTracker, "detect"), (jobs, "load_view")):
        original = getattr(owner, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            counts[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(owner, name, counted)
    if not stored:
        monkeypatch.setattr(jobs._GridViews, "_stored", lambda *args: None)
    (job,) = plan.home
    assert run_home_job(job, run_dir).error is None
    monkeypatch.undo()
    rows = read_result(job.result_path(run_dir), job.key)["rows"]
    return {**counts, "currents": len(job.currents), "ae": [row["ae"] for row in rows],
            "estimates": [row["estimate"] for row in rows]}  # fmt: skip


def test_a_tree_of_routes_tracks_once_per_current(tmp_path, arena_manifest, monkeypatch):
    tree = _run(tmp_path / "tree", arena_manifest, "tree", monkeypatch)
    line = _run(tmp_path / "line", arena_manifest, "line", monkeypatch)
    assert tree["step"] == tree["currents"]
    assert line["step"] > tree["step"]
    # route views are read for their images: no corners detected in a home job
    assert tree["detect"] == line["detect"] == 0
    assert None not in tree["ae"] and None not in line["ae"]


def test_route_views_come_from_the_current_views_feature_files(
    tmp_path, arena_manifest, monkeypatch
):
    """Every route view of an all-currents job is a described current view: no image is read
    again, and the estimates are those of route views described in the job."""
    stored = _run(tmp_path / "stored", arena_manifest, "tree", monkeypatch)
    fresh = _run(tmp_path / "fresh", arena_manifest, "tree", monkeypatch, stored=False)
    assert stored["load_view"] == 0 < fresh["load_view"]
    assert stored["estimates"] == fresh["estimates"]
