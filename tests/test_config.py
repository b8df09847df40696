"""The run config: strict validation with errors that name the file and the key path."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from homebench.config import load_config
from homebench.errors import ConfigError

VALID = {
    "name": "t",
    "output": "runs/t",
    "databases": {"a": {"world": {"grid": {"shape": [3, 3]}}}, "b": "synth-original"},
    "conditions": ["a-a", "a-b"],
    "goals": [[1, 1]],
    "methods": [
        {"method": "warping"},
        {"method": "warping", "label": "w2", "params": {"n_rho": 5}},
    ],
}


def _write(tmp_path: Path, data: object) -> Path:
    path = tmp_path / "config.yaml"
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def _with(**changes: object) -> dict:
    data = dict(VALID)
    data.update(changes)
    return data


def test_valid_config_loads(tmp_path: Path) -> None:
    config = load_config(_write(tmp_path, VALID))
    assert config.databases["b"].name == "synth-original"
    assert config.condition_pairs() == [("a-a", "a", "a"), ("a-b", "a", "b")]
    assert [m.name for m in config.methods] == ["warping", "w2"]
    assert config.metrics.return_ratio.rh == 0.8


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"colour": "red"}, "colour: Extra inputs are not permitted"),
        ({"jobs": -3}, "jobs: jobs must be a positive number"),
        ({"jobs": "many"}, "jobs: Input should be a valid integer"),
        ({"conditions": ["a-c"]}, "unknown database alias 'c'"),
        ({"conditions": ["a"]}, "is not 'current-goal'"),
        ({"methods": [{"method": "warping"}, {"method": "warping"}]}, "label 'warping' used twice"),
        ({"methods": [{"method": "teleport"}]}, "methods.0: unknown method 'teleport'"),
        (
            {"methods": [{"method": "warping", "params": {"n_rhoo": 3}}]},
            "has no parameter(s) n_rhoo",
        ),
        ({"currents": {"min_distance": 2, "max_distance": 1}}, "max_distance must not be below"),
        ({"databases": {"a-1": "synth-original"}, "conditions": ["a-1"]}, "aliases may hold"),
    ],
)
def test_invalid_configs_name_file_and_key(tmp_path: Path, changes: dict, message: str) -> None:
    path = _write(tmp_path, _with(**changes))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(path) in str(info.value)
    assert message in str(info.value)


def test_yaml_syntax_error_gives_line_and_column(tmp_path: Path) -> None:
    path = _write(tmp_path, "name: t\nmethods: [warping\n")
    with pytest.raises(ConfigError, match=r"config.yaml:\d+:\d+: YAML syntax error"):
        load_config(path)


def test_empty_and_missing_files(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="empty"):
        load_config(_write(tmp_path, ""))
    with pytest.raises(ConfigError, match="no such config"):
        load_config(tmp_path / "absent.yaml")
