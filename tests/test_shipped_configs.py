"""The configs in configs/ load, and the smoke benchmark passes its own checks end to end."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from conftest import run_config

from homebench.config import RunConfig
from homebench.experiments.closed_loop.config import ClosedLoopConfig
from homebench.experiments.config_files import validated_config
from homebench.yamlio import read_yaml

CONFIGS = sorted((Path(__file__).parent.parent / "configs").glob("*.yaml"))


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_shipped_config_is_valid(path: Path) -> None:
    config = validated_config(read_yaml(path, "config"))
    if isinstance(config, RunConfig):
        assert config.methods
    elif isinstance(config, ClosedLoopConfig):
        assert config.labels()
    else:
        assert config.routes


@pytest.mark.slow  # CI time: .ci/run runs `homebench run configs/smoke.yaml --check` itself
def test_smoke_benchmark_passes_its_checks(tmp_path: Path) -> None:
    data = yaml.safe_load((Path(__file__).parent.parent / "configs" / "smoke.yaml").read_text())
    data["output"] = str(tmp_path / "smoke")
    result = run_config(tmp_path, data, "--check", report=True)
    assert result.exit_code == 0, result.output
    assert "all 4 method check(s) passed" in result.stdout
    assert (tmp_path / "smoke" / "report" / "report.pdf").is_file()
