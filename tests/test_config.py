"""The run config: strict validation with errors that name the file and the key path."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from conftest import write_arena_database

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
        ({"seeds": [1, 2**63]}, "seeds: seeds must be distinct, non-negative and at most"),
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


def test_overrides_set_keys_list_items_and_new_keys(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "output": "out",
                "databases": {"a": "synth-original"},
                "conditions": ["a-a"],
                "goals": [[1, 1]],
                "methods": [{"method": "sift"}, {"method": "warping"}],
            }
        )
    )
    config = load_config(
        path, ["methods.0.params.ratio=0.7", "goals=all", "output=elsewhere", "seeds=[1, 2]"]
    )
    assert config.method_points()[0] == ("sift", "sift", {"ratio": 0.7})
    assert config.goals == "all" and str(config.output) == "elsewhere" and config.seeds == [1, 2]
    for bad, message in [
        ("goals", "expected key.path=value"),
        ("methods.5.params.ratio=1", r"methods\.5 is not a key or index"),
        ("methods.0.params.bogus=1", "bogus"),
        ("goals=[1, 2", "override"),
    ]:
        with pytest.raises(ConfigError, match=message):
            load_config(path, [bad])


def test_cli_overrides_are_applied_and_recorded(tmp_path):
    from test_run import _config, _run

    manifest = write_arena_database(tmp_path / "arena")
    config = _config(tmp_path, manifest)
    code, _, err = _run(str(config), "goals=[[0, 0]]", "output=" + str(tmp_path / "other"))
    assert code == 0, err
    resolved = json.loads((tmp_path / "other" / "config.resolved.json").read_text())
    assert resolved["goals"] == [[0, 0]]
    environment = json.loads((tmp_path / "other" / "environment.json").read_text())
    assert environment["overrides"]["config"] == ["goals=[[0, 0]]", f"output={tmp_path / 'other'}"]


@pytest.mark.parametrize(
    ("kind", "data", "meant"),
    [
        ("route", {"routes": [{"name": "a", "waypoints": [[1, 1], [1, 2]]}],
                   "sucess_radius_m": 0.2}, "success_radius_m"),
        ("closed-loop", {"goals": [{"at": [1, 1]}], "starts": {"spacing": 0.5},
                         "motoin": {}}, "motion"),
    ],
)  # fmt: skip
def test_robot_configs_name_the_key_meant(tmp_path: Path, kind: str, data: dict, meant: str):
    """Route and closed-loop configs share the grid config's strict base: a misspelt key names
    the key meant."""
    from homebench.experiments.closed_loop.config import load_closed_loop_config
    from homebench.experiments.route.config import load_route_config

    load = load_route_config if kind == "route" else load_closed_loop_config
    path = _write(tmp_path, {"kind": kind, "output": "runs/r", **data})
    with pytest.raises(ConfigError, match=rf"did you mean '{meant}'"):
        load(path)
