"""A real database's identity covers what its manifest says of its images: correcting a heading
or the camera model (as `homebench data check` asks) recomputes the run's features and pairs;
an unchanged manifest reuses them. Before, the identity was the folder alone, so a rerun after a
correction silently kept every result computed with the wrong heading or camera."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from bob_folders import write_grid
from conftest import run_config
from test_database import USER_MANIFEST, make_user_database


def _counts(output: str) -> tuple[int, int]:
    """(computed, reused) jobs of a run's summary line."""
    found = re.search(r"(\d+) job\(s\) computed, (\d+) reused", output)
    assert found, output
    return int(found[1]), int(found[2])


def _config(database: Path, output: Path) -> dict:
    return {
        "name": "identity",
        "output": str(output),
        "databases": {"db": str(database)},
        "conditions": ["db-db"],
        "goals": [[1, 0]],
        "methods": [{"method": "warping"}],
    }


def _truths(run: Path) -> pd.Series:
    pairs = pd.read_csv(run / "tables" / "pairs.csv")
    return pairs.set_index(["current_i", "current_j"])["truth_deg"]


def test_a_corrected_manifest_recomputes_and_an_unchanged_one_reuses(tmp_path: Path) -> None:
    root = make_user_database(tmp_path / "corridor")
    config = _config(root / "manifest.yaml", tmp_path / "run")
    first = run_config(tmp_path, config)
    assert first.exit_code == 0, first.output
    assert _counts(first.output) == (1, 0)
    before = _truths(tmp_path / "run")
    again = run_config(tmp_path, config)
    assert _counts(again.output) == (0, 1)
    # the user corrects the shared heading by 10 degrees: every true direction turns by -10
    (root / "manifest.yaml").write_text(
        USER_MANIFEST.replace("heading_deg: 45.0", "heading_deg: 55.0")
    )
    corrected = run_config(tmp_path, config)
    assert corrected.exit_code == 0, corrected.output
    assert _counts(corrected.output) == (1, 0)
    turned = (before - _truths(tmp_path / "run") + 180) % 360 - 180
    unchanged = np.array([index == (1, 1) for index in turned.index])  # its own heading
    assert (abs(turned[~unchanged] - 10) < 1e-6).all() and (abs(turned[unchanged]) < 1e-6).all()
    # and the camera model: the zero column
    (root / "manifest.yaml").write_text(USER_MANIFEST.replace("zero_column: 5", "zero_column: 9"))
    assert _counts(run_config(tmp_path, config).output) == (1, 0)


def test_a_bob_folders_homebench_yaml_is_part_of_its_identity(tmp_path: Path) -> None:
    folder = write_grid(tmp_path / "arena")
    config = _config(folder, tmp_path / "run")
    assert _counts(run_config(tmp_path, config).output) == (1, 0)
    assert _counts(run_config(tmp_path, config).output) == (0, 1)
    panorama = {"elevation_top_deg": 30.0, "elevation_bottom_deg": -30.0, "zero_column": 3.0}
    (folder / "homebench.yaml").write_text(
        yaml.safe_dump({"images": {"unfolded": {"panorama": panorama}}})
    )
    assert _counts(run_config(tmp_path, config).output) == (1, 0)
    # a copy of the folder elsewhere is another database (its own features), as before
    shutil.copytree(folder, tmp_path / "copy")
    copied = run_config(tmp_path, _config(tmp_path / "copy", tmp_path / "run2"))
    assert _counts(copied.output) == (1, 0)
