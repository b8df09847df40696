"""A method entry's ``compass`` (engine level, any method): runs, keys and config errors.

The arena database's images are all taken at one heading, so a current view turned by the
run's ``rotate_current`` differs from the stored one by a whole number of columns and nothing
else. Tolerances:

- ``compass: visual`` on a turned view against the same entry on the stored view: the RIDF of a
  view rolled by k columns is the RIDF of the stored view shifted by k (the FFT's rounding,
  ~1e-12 of the values, could only flip an exact tie), so the view turned back is the stored
  view and the world-frame estimate is the same to rounding: 1e-9 rad.
- ``compass: truth`` on a turned view against ``none`` on the stored view: the true heading
  change is the whole-column turn, so the method sees the stored view: exact to rounding.
- ``compass: visual`` against the paper's aligned views (``none``) on the stored views: the
  compass's parallax error (here 5.6 deg on average, at most 13.8 deg) turns the landmark
  bearings by as much, and a sector that changes between the views turns the ALV further;
  measured on ALV over the 38 pairs: the home direction moves 3.9 deg on average, 23.0 deg at
  most; the test allows a mean of 8 and a largest change of 30 deg.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import arena_config, run_config

from homebench.config import load_config
from homebench.errors import ConfigError
from homebench.evaluation.plan import described, make_plan, method_specs
from homebench.evaluation.results import load_pairs
from homebench.evaluation.sources import prepare_sources
from homebench.fileio import read_grey, write_png
from homebench.geometry import angle_diff
from homebench.hashing import stable_hash

ALV_ENTRIES = [
    {"method": "alv"},
    {"method": "alv", "label": "alv-visual", "compass": "visual"},
    {"method": "alv", "label": "alv-truth", "compass": "truth"},
]


def _pairs(folder: Path, manifest: Path, rotate: bool) -> pd.DataFrame:
    folder.mkdir()
    rotation = {"enabled": rotate, "seed": 3}
    config = arena_config(folder, manifest, methods=ALV_ENTRIES, rotate_current=rotation)
    result = run_config(folder, config)
    assert result.exit_code == 0, result.output
    pairs = load_pairs(folder / "run").pairs
    return pairs.set_index(["method", "goal_i", "goal_j", "current_i", "current_j"])


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory, arena_manifest: Path) -> dict:
    root = tmp_path_factory.mktemp("compass")
    return {
        "stored": _pairs(root / "stored", arena_manifest, rotate=False),
        "turned": _pairs(root / "turned", arena_manifest, rotate=True),
    }


def _world(pairs: pd.DataFrame, label: str) -> np.ndarray:
    return pairs.loc[label, "estimate_world"].to_numpy(dtype=float)


def test_the_visual_compass_undoes_a_turn_of_the_current_view(runs):
    stored, turned = runs["stored"], runs["turned"]
    assert (turned.loc["alv", "rotation"] != 0).any()  # seeded by the database path
    difference = angle_diff(_world(turned, "alv-visual"), _world(stored, "alv-visual"))
    np.testing.assert_allclose(difference, 0.0, atol=1e-9)
    # the compass's turn is the recorded rotation estimate: the turn plus the stored one's
    recorded = angle_diff(
        turned.loc["alv-visual", "rotation_estimate"].to_numpy(dtype=float),
        stored.loc["alv-visual", "rotation_estimate"].to_numpy(dtype=float),
    )
    # as angles: a half turn reads +pi on one side and -pi on the other after rounding
    turn = turned.loc["alv", "rotation"].to_numpy(dtype=float)
    np.testing.assert_allclose(angle_diff(recorded, turn), 0.0, atol=1e-9)


def test_without_a_compass_the_turn_changes_the_answer(runs):
    difference = angle_diff(_world(runs["turned"], "alv"), _world(runs["stored"], "alv"))
    assert np.max(np.abs(difference)) > math.radians(30.0)
    assert runs["stored"].loc["alv", "rotation_estimate"].isna().all()


def test_the_true_compass_gives_the_paper_s_aligned_answer(runs):
    difference = angle_diff(_world(runs["turned"], "alv-truth"), _world(runs["stored"], "alv"))
    np.testing.assert_allclose(difference, 0.0, atol=1e-9)
    truth = runs["turned"].loc["alv-truth"]
    np.testing.assert_allclose(truth["rotation_error"].to_numpy(dtype=float), 0.0, atol=1e-9)


def test_the_visual_compass_costs_a_few_degrees_on_aligned_views(runs):
    stored = runs["stored"]
    change = np.abs(angle_diff(_world(stored, "alv-visual"), _world(stored, "alv")))
    assert np.mean(change) < math.radians(8.0) and np.max(change) < math.radians(30.0)
    ae = stored.loc["alv-visual", "ae"].to_numpy(dtype=float)
    assert np.isfinite(ae).all()


def _plan(folder: Path, config: dict):
    path = folder / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    loaded = load_config(path)
    return loaded, make_plan(loaded, prepare_sources(loaded, jobs=1), path)


def test_keys_differ_with_and_without_a_compass(tmp_path: Path, arena_manifest: Path):
    config, plan = _plan(tmp_path, arena_config(tmp_path, arena_manifest, methods=ALV_ENTRIES))
    specs = method_specs(config)
    assert len({spec.key for spec in specs}) == 3
    none = specs[0]
    # an entry without a compass keeps the key of earlier versions: its results stay valid
    assert none.key == stable_hash(
        {"method": none.method, "params": dict(none.params), "code": none.code}
    )
    by_label = {job.method.label: job for job in plan.home if job.goal.i == 1}
    assert len({job.key for job in by_label.values()}) == 3
    # with a compass the current views are described in the home job: describe jobs hold goals
    assert described(by_label["alv-visual"]) == (by_label["alv-visual"].goal,)
    assert len(described(by_label["alv"])) == 1 + len(by_label["alv"].currents)


def test_a_compass_in_params_names_the_entry_key(tmp_path: Path, arena_manifest: Path):
    entries = [{"method": "alv", "params": {"compass": "visual"}}]
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(arena_config(tmp_path, arena_manifest, methods=entries)))
    with pytest.raises(ConfigError, match=r"methods\.0: params: compass is a key of the method"):
        load_config(path)


def test_an_unknown_compass_is_a_config_error(tmp_path: Path, arena_manifest: Path):
    entries = [{"method": "alv", "compass": "magnetic"}]
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, methods=entries))
    assert result.exit_code == 2 and "compass" in result.output


def test_a_changed_neighbour_image_recomputes_did(tmp_path: Path, arena_manifest: Path):
    """DID reads the current views' grid neighbours: with currents 0.3 m from the goal (1, 2),
    the view at (1, 4) is no pair's image but the neighbour of current (1, 3)."""
    database = tmp_path / "arena"
    shutil.copytree(arena_manifest.parent, database)
    methods = [{"method": "did"}, {"method": "warping", "params": {"n_rho": 4}}]
    config = arena_config(
        tmp_path,
        database / "manifest.yaml",
        goals=[[1, 2]],
        currents={"max_distance": 0.31},
        methods=methods,
    )
    assert run_config(tmp_path, config).exit_code == 0
    image = database / "pano" / "p1-4.png"
    write_png(image, 255 - read_grey(image))
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "1 job(s) computed, 1 reused" in result.stdout
