"""A run says when its data differ from their reference sums, and how."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from conftest import run_config
from test_database import make_user_database
from test_generate import small_spec

from homebench.cli import main
from homebench.data.generate import generate
from homebench.data.verify import record_sums
from homebench.evaluation.data_checks import DataCheck
from homebench.fileio import read_grey, write_png

METHODS = [{"method": "warping", "params": {"n_psi": 36, "n_alpha": 36, "n_columns": 36}}]


def _reference(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, edit) -> Path:
    """A shipped-like manifest 'tiny' (a real generation's sums and fingerprints) with
    ``edit(manifest_dict)`` applied, in a manifest folder the catalog searches first."""
    generated = generate(small_spec(seed=4), tmp_path / "reference", 1, "tiny")
    data = yaml.safe_load((generated / "manifest.yaml").read_text())
    edit(data["images"]["unfolded"])
    folder = tmp_path / "manifests"
    folder.mkdir()
    (folder / "tiny.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    monkeypatch.setenv("HOMEBENCH_MANIFESTS", str(folder))
    return folder


def _run(tmp_path: Path):
    config = {
        "output": str(tmp_path / "run"),
        "databases": {"a": "tiny"},
        "conditions": ["a-a"],
        "goals": [[1, 1]],
        "methods": METHODS,
    }
    return run_config(tmp_path, config)


def test_identical_data_give_no_note(tmp_path, monkeypatch):
    _reference(tmp_path, monkeypatch, lambda section: None)
    result = _run(tmp_path)
    assert result.exit_code == 0, result.output
    assert "note" not in result.output
    environment = json.loads((tmp_path / "run" / "environment.json").read_text())
    (check,) = environment["data_checks"].values()
    assert check["identical"] == check["checked"] == 12 + 12


def test_another_processors_rounding_and_real_differences_are_told_apart(tmp_path, monkeypatch):
    """The reference machine's sums differ for two files whose fingerprints match (rounding)
    and for one whose fingerprint does not (content)."""

    def edit(section: dict) -> None:
        for name in ("0_0.png", "1_1.png", "2_3.png"):
            section["files"][name] = "0" * 64
        mean, gradient, bits = section["fingerprints"]["2_3.png"].split(":")
        section["fingerprints"]["2_3.png"] = f"{int(mean) + 500}:{gradient}:{bits}"

    _reference(tmp_path, monkeypatch, edit)
    result = _run(tmp_path)
    assert result.exit_code == 0, result.output
    note = next(line for line in result.output.splitlines() if "note" in line)
    assert "a: 21 of 24 files byte-identical to the shipped reference sums" in note
    assert "2 differ in bytes but match their content fingerprints" in note
    assert "1 differ in content (unfolded/2_3.png)" in note


def test_a_real_sets_changed_file_is_noted(tmp_path):
    root = make_user_database(tmp_path / "corridor")
    record_sums(root / "manifest.yaml", root)
    image = read_grey(root / "pano" / "img-001-001.png")
    write_png(root / "pano" / "img-001-001.png", np.flipud(image).copy())
    config = {
        "output": str(tmp_path / "run"),
        "databases": {"c": str(root / "manifest.yaml")},
        "conditions": ["c-c"],
        "goals": [[1, 0]],
        "methods": METHODS,
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "c: 5 of 6 files byte-identical to the manifest's sums" in result.output
    assert "1 differ in content (pano/img-001-001.png)" in result.output


def test_notes_name_a_few_files_and_count_the_rest():
    check = DataCheck("x", "the manifest's sums", 10, 5, 0, tuple(f"f{k}" for k in range(5)))
    assert "5 differ in content (f0, f1, f2 and 2 more)" in check.note()
    assert DataCheck("x", "r", 3, 3, 0, ()).note() is None


def _rounded_elsewhere(section: dict) -> None:
    """The reference machine's bytes differ for two files, their content does not."""
    for name in ("0_0.png", "1_1.png"):
        section["files"][name] = "0" * 64


def test_a_generated_set_equal_in_content_is_not_told_on_every_run(tmp_path, monkeypatch):
    """Bytes that differ from the reference machine's while the content matches are what a
    generated set looks like on another processor: `data verify` says so (below); a run says
    nothing, and records the comparison in environment.json."""
    assert DataCheck("x", "r", 4, 2, 2, ()).note() is None
    _reference(tmp_path, monkeypatch, _rounded_elsewhere)
    result = _run(tmp_path)
    assert result.exit_code == 0, result.output
    assert "note" not in result.output and "differ" not in result.output
    environment = json.loads((tmp_path / "run" / "environment.json").read_text())
    (check,) = environment["data_checks"].values()
    assert (check["identical"], check["tolerated"]) == (22, 2)


def test_data_verify_words_a_generated_sets_other_bytes_as_expected(tmp_path, monkeypatch):
    _reference(tmp_path, monkeypatch, _rounded_elsewhere)
    runner = CliRunner()
    assert runner.invoke(main, ["data", "generate", "tiny", "--no-progress"]).exit_code == 0
    result = runner.invoke(main, ["data", "verify", "tiny"])
    assert result.exit_code == 0, result.output
    (line,) = result.stdout.splitlines()
    assert line.startswith("tiny: 24 images OK in ") and "generated" in line
    assert "22 byte-identical to the shipped reference" in line
    assert "2 equal to it in content" in line and "expected" in line
    assert "differing in bytes" not in line and result.stderr == ""
