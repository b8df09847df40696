"""One run folder, one run: a folder in use is refused (an OS lock, gone with its process), and
so is a folder holding another config's run unless ``--force``."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import arena_config, run_config
from plugins import install_plugin

from homebench.evaluation.run_folder import RunFolderInUseError, lock_run_folder


def test_shards_share_a_folder_a_whole_run_does_not(tmp_path: Path) -> None:
    def busy(shared: bool) -> bool:
        try:
            with lock_run_folder(tmp_path, shared):
                return False
        except RunFolderInUseError:
            return True

    with lock_run_folder(tmp_path, shared=True):
        assert not busy(shared=True) and busy(shared=False)
    with lock_run_folder(tmp_path):
        assert busy(shared=True) and busy(shared=False)
    assert not busy(shared=False)  # released when its holder leaves


def test_a_folder_in_use_is_refused_until_its_run_ends(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from homebench.data.catalog import resolve

    plugin = install_plugin(tmp_path / "plugin", monkeypatch)
    hang = float(np.mean(resolve(str(arena_manifest)).image(1, 2, "unfolded")))
    methods = [{"method": plugin.method, "params": {"hang_goal": hang}}]
    config = arena_config(tmp_path, arena_manifest, methods=methods, job_timeout_s=600)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    command = [sys.executable, "-m", "homebench", "run", str(path), "--no-progress", "--no-report"]
    first = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not (tmp_path / "run" / "plan.json").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        start = time.monotonic()
        result = run_config(tmp_path, config)
        assert result.exit_code == 2, result.output
        assert time.monotonic() - start < 10
        assert "in use by another homebench run" in result.stderr
        assert len(result.stderr.strip().splitlines()) == 1
    finally:
        os.kill(first.pid, signal.SIGKILL)
        first.wait()
    result = run_config(tmp_path, config, "--timeout", "2")
    assert result.exit_code == 1, result.output
    assert "timed out after 2 s" in result.stderr


def test_another_configs_folder_is_refused_unless_forced(
    tmp_path: Path, arena_manifest: Path
) -> None:
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": "warping"}])
    assert run_config(tmp_path, config).exit_code == 0
    assert run_config(tmp_path, config, "--jobs", "2").exit_code == 0  # same config, run anew
    other = {**config, "goals": [[0, 0]]}
    result = run_config(tmp_path, other)
    assert result.exit_code == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert str(tmp_path / "run" / "config.resolved.json") in result.stderr
    assert "--force" in result.stderr
    result = run_config(tmp_path, other, "--force")
    assert result.exit_code == 0, result.output
    assert "1 job(s) computed, 0 reused" in result.stdout
