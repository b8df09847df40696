"""Provenance: environment.json says where the results come from, config.resolved.json which
values were used."""

from __future__ import annotations

import json
import re
import sys
from importlib.metadata import version
from pathlib import Path

import pytest
from conftest import arena_config, run_config
from plugins import install_plugin

from homebench.data.manifest import load_manifest
from homebench.evaluation.provenance import git_state
from homebench.hashing import stable_hash
from homebench.methods import registry


def test_environment_and_resolved_config_record_what_was_used(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugin = install_plugin(tmp_path / "plugin", monkeypatch)
    methods = [{"method": plugin.method}, {"method": "warping", "params": {"n_rho": 8}}]
    config = arena_config(tmp_path, arena_manifest, methods=methods, jobs=2)
    result = run_config(tmp_path, config, "--jobs", "1", "--timeout", "300")
    assert result.exit_code == 0, result.output
    run_dir = tmp_path / "run"
    environment = json.loads((run_dir / "environment.json").read_text())
    git = environment["git"]
    assert re.fullmatch("[0-9a-f]{40}", git["commit"]) and isinstance(git["dirty"], bool)
    assert environment["cpu"]["model"]
    assert environment["distributions"]["numpy"] == version("numpy")
    assert environment["distributions"][plugin.distribution] == "1.0"
    warping, faulty = environment["methods"]["warping"], environment["methods"][plugin.method]
    assert warping["distribution"] == "homebench" and warping["version"] == version("homebench")
    assert faulty["distribution"] == plugin.distribution and faulty["version"] == "1.0"
    assert faulty["code_version"].startswith(f"{plugin.distribution} 1.0 ")
    manifest = load_manifest(arena_manifest).model_dump(mode="json")
    assert environment["databases"]["arena"]["manifest_sha256"] == stable_hash(manifest, 64)
    assert environment["command"] == sys.argv
    assert environment["overrides"]["jobs"] == 1
    assert environment["overrides"]["job_timeout_s"] == 300
    load = environment["load"]  # the host's 1-min load average as the run call began and ended
    assert load["start_1min"] >= 0 and load["end_1min"] >= 0
    assert load["jobs_timed"] > 0 and load["jobs_reused"] == 0

    resolved = json.loads((run_dir / "config.resolved.json").read_text())
    assert resolved["jobs"] == 1
    assert resolved["job_timeout_s"] == 300
    defaults = json.loads(json.dumps(registry.parameters(plugin.method)))  # tuples as lists
    assert resolved["methods"][0]["params"] == defaults
    assert resolved["methods"][1]["params"] == {**registry.parameters("warping"), "n_rho": 8}


def test_git_state_is_none_outside_a_git_checkout(tmp_path: Path) -> None:
    assert git_state(tmp_path) is None


def test_a_built_in_methods_distribution_is_found_without_reading_every_distribution(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """homebench declares its top-level module, so its methods' origin needs no scan of all
    installed distributions' metadata (a tenth of a second of every run's main process)."""

    def scan() -> dict[str, list[str]]:
        raise AssertionError("every installed distribution was read")

    monkeypatch.setattr(registry, "_distributions", scan)
    registry._declaring.cache_clear()
    warping = registry.get("warping")
    assert registry.distribution(warping) == ("homebench", version("homebench"))
