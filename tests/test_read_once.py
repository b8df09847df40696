"""A run reads its config file once and each manifest once a lookup (issue 41).

Before, ``homebench run`` read the config to learn its kind (``config_kind``) and again to
validate it (``load_config``), and a manifest lookup took the file's status and then opened it
(``load_manifest``, then ``_load_unchanged``): a file rewritten between the two, or rewritten
with its size and modification time kept, was answered from the cache with its old content.
"""

from __future__ import annotations

import os
import shutil
from collections import Counter
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import arena_config, run_config

from homebench import yamlio
from homebench.cli import main
from homebench.data import manifest as manifest_module
from homebench.errors import ConfigError
from homebench.experiments.route import experiment as route_experiment

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> Counter[str]:
    """How often each YAML file (config or manifest) is read, by name."""
    counts: Counter[str] = Counter()
    read = yamlio._read

    def counted(path: Path, what: str) -> str:
        counts[Path(path).name] += 1
        return read(path, what)

    monkeypatch.setattr(yamlio, "_read", counted)
    return counts


def test_a_grid_run_reads_its_config_once(
    tmp_path: Path, arena_manifest: Path, reads: Counter[str]
) -> None:
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, goals=[[1, 2]]))
    assert result.exit_code == 0, result.output
    assert reads["config.yaml"] == 1


def test_a_route_run_reads_its_config_once_with_the_timeout_applied(
    tmp_path: Path, reads: Counter[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = []

    def stop(config: object, *args: object, **kwargs: object) -> None:
        seen.append(config)
        raise ConfigError("stopped before the first trial")

    monkeypatch.setattr(route_experiment, "run_route_experiment", stop)
    path = tmp_path / "route.yaml"
    shutil.copy(CONFIGS / "route_methods.yaml", path)
    result = CliRunner().invoke(main, ["run", str(path), "--timeout", "30", "--no-progress"])
    assert result.exit_code == 2 and "stopped before the first trial" in result.output
    assert reads["route.yaml"] == 1
    assert [config.job_timeout_s for config in seen] == [30.0]


def test_a_manifest_rewritten_with_its_size_and_time_kept_is_read_again(tmp_path: Path) -> None:
    path = tmp_path / "manifest.yaml"
    shutil.copy(CONFIGS.parent / "data_manifests" / "synth-original.yaml", path)
    assert manifest_module.load_manifest(path).name == "synth-original"
    status = path.stat()
    path.write_text(path.read_text().replace("name: synth-original", "name: synth-origin4l", 1))
    os.utime(path, ns=(status.st_atime_ns, status.st_mtime_ns))
    assert path.stat().st_size == status.st_size
    assert manifest_module.load_manifest(path).name == "synth-origin4l"
