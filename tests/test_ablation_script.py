"""scripts/ablation.py end to end: two camera levels of a 4 x 5 world, one cheap method."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "ablation.py"
BASE = {
    "name": "tiny",
    "output": "unused",
    "jobs": 1,
    "databases": {"original": {"world": {"grid": {"shape": [4, 5]}}}},
    "conditions": ["original-original"],
    "goals": [[1, 1], [2, 3]],
    "methods": [{"method": "warping"}],
}
LEVELS = {"reference": "default", "levels": {"default": {}, "sharp": {"blur_deg": 0}}}


@pytest.fixture(scope="module")
def ablation():
    spec = importlib.util.spec_from_file_location("ablation_script", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # pydantic resolves the script's annotations there
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow  # 7-30 s: two worlds generated and run, by load
def test_two_levels_run_and_compare_on_the_same_pairs(ablation, tmp_path: Path) -> None:
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "levels.yaml").write_text(yaml.safe_dump(LEVELS))
    out, report = tmp_path / "out", tmp_path / "report"
    files = ["--config", str(tmp_path / "base.yaml"), "--levels", str(tmp_path / "levels.yaml")]
    ablation.main(["run", "--out", str(out), *files, "styles=[lab]"])
    written = yaml.safe_load((out / "configs" / "sharp.yaml").read_text())
    assert written["databases"]["original"]["world"]["camera"] == {"blur_deg": 0}
    assert written["output"] == str(out / "sharp") and written["styles"] == ["lab"]
    assert set(json.loads((out / "timing.json").read_text())) == {"default", "sharp"}
    ablation.main(["analyse", "--out", str(out), "--report", str(report)])
    changes = pd.read_csv(report / "changes.csv")
    assert set(changes["place"]) == {"lab"} and set(changes["level"]) == {"sharp"}
    assert (changes["n_pairs"] == 2 * 19).all() and (changes["n_goals"] == 2).all()
    summary = pd.read_csv(report / "ahc.csv")
    assert list(summary["level"]) == ["default", "sharp"]
    assert "| warping " in (report / "ahc.md").read_text()


def test_levels_that_differ_in_more_than_the_camera_are_refused(ablation, tmp_path: Path):
    configs = {}
    for name, grid in (("a", [4, 5]), ("b", [4, 6])):
        config = {"databases": {"x": {"world": {"grid": grid, "camera": {}}}}, "output": name}
        configs[name] = tmp_path / f"{name}.json"
        configs[name].write_text(json.dumps(config))
    with pytest.raises(SystemExit, match=r"levels \['b'\] differ"):
        ablation._same_but_camera(configs)


def test_only_takes_one_level_each_and_refuses_unknown_ones(ablation, tmp_path: Path):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "levels.yaml").write_text(yaml.safe_dump(LEVELS))
    files = ["--config", str(tmp_path / "base.yaml"), "--levels", str(tmp_path / "levels.yaml")]
    # the override after --only stays an override (not a level name)
    with pytest.raises(SystemExit, match=r"--only \['nope'\]: not levels"):
        ablation.main(["run", "--out", str(tmp_path / "out"), *files, "--only", "nope", "jobs=1"])
