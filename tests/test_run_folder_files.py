"""What is read from a run folder is checked against its schema: a job file of the wrong shape
is recomputed by `run` and a missing result to every reader; a folder file of the wrong shape
(the plan, the resolved config) is one line naming it, exit 2. Nothing crashes."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result
from conftest import arena_config, run_config

from homebench.cli import main

DEEP = "[" * 100_000 + "]" * 100_000


@pytest.fixture
def run_dir(tmp_path: Path, arena_manifest: Path) -> Path:
    """A finished arena run of warping (two goals: two job files) in ``tmp_path``, its config
    in ``tmp_path / "config.yaml"``; its folder."""
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": "warping"}])
    assert run_config(tmp_path, config).exit_code == 0
    return tmp_path / "run"


def _rerun(tmp_path: Path) -> Result:
    return _invoke("run", str(tmp_path / "config.yaml"), "--no-progress", "--no-report")


def _first_row(field: str, value: Any) -> Callable[[dict], None]:
    def change(record: dict) -> None:
        record["rows"][0][field] = value

    return change


def _field(field: str, value: Any) -> Callable[[dict], None]:
    def change(record: dict) -> None:
        record[field] = value

    return change


DAMAGE = {
    "ae-text": _first_row("ae", "NaNx"),
    "current-outside-the-grid": _first_row("current_i", 99),
    "negative-current": _first_row("current_j", -1),
    "times-text": _first_row("home_ms", "fast"),
    "goal-text": _field("goal_i", "a"),
    "goal-outside-the-grid": _field("goal_j", 17),
    "rows-not-a-list": _field("rows", {"a": 1}),
    "grid-shape": _field("grid", {"shape": ["x"], "spacing": 0.3, "origin": [0, 0]}),
    "no-gives-direction": lambda record: record.pop("gives_direction"),
    "database-key": _field("goal_database_key", 7),
}


def _invoke(*args: str) -> Result:
    return CliRunner().invoke(main, list(args))


@pytest.mark.parametrize("damage", list(DAMAGE), ids=list(DAMAGE))
def test_a_job_file_of_the_wrong_shape_is_recomputed_and_read_as_missing(
    run_dir: Path, tmp_path: Path, damage: str
) -> None:
    victim = sorted((run_dir / "jobs").glob("*.json"))[0]
    record = json.loads(victim.read_text())
    DAMAGE[damage](record)
    victim.write_text(json.dumps(record))
    for args in (
        ["report", str(run_dir), "--format", "md", "--no-progress"],
        ["leaderboard", str(run_dir)],
        ["findings", str(run_dir)],
    ):
        result = _invoke(*args)
        assert result.exit_code in (0, 2), (args, result.output)
        assert "crash" not in result.stderr, (args, result.stderr)
    report = _invoke("report", str(run_dir), "--format", "md", "--no-progress")
    assert f"missing job result jobs/{victim.name}" in report.stderr
    result = _rerun(tmp_path)
    assert result.exit_code == 0, result.output
    assert "1 job(s) computed, 1 reused" in result.stdout
    assert json.loads(victim.read_text()) != record


def test_a_job_file_nested_100000_deep_is_recomputed(run_dir: Path, tmp_path: Path) -> None:
    victim = sorted((run_dir / "jobs").glob("*.json"))[0]
    victim.write_text(DEEP)
    report = _invoke("report", str(run_dir), "--format", "md", "--no-progress")
    assert report.exit_code == 0, report.output
    assert f"missing job result jobs/{victim.name}" in report.stderr
    result = _rerun(tmp_path)
    assert result.exit_code == 0, result.output
    assert "1 job(s) computed, 1 reused" in result.stdout


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("config.resolved.json", DEEP),
        ("plan.json", DEEP),
        ("plan.json", '[{"key": "../../../etc/passwd", "condition": "a-a", "method": "m"}]'),
        ("plan.json", '[{"key": 1}]'),
        ("plan.json", '{"key": "a"}'),
    ],
)
def test_a_folder_file_of_the_wrong_shape_is_one_line_naming_it(
    run_dir: Path, tmp_path: Path, name: str, text: str
) -> None:
    """run reads config.resolved.json (whose config the folder holds), so do the readers of
    runs; report reads the plan."""
    (run_dir / name).write_text(text)
    commands = [
        ["run", str(tmp_path / "config.yaml"), "--no-progress", "--no-report"],
        ["report", str(run_dir), "--format", "md", "--no-progress"],
        ["compare", str(run_dir), str(run_dir), "--label", "a", "--label", "b"],
        ["leaderboard", str(run_dir)],
        ["findings", str(run_dir)],
    ]
    if name == "plan.json":
        commands = commands[1:2]
    for args in commands:
        result = _invoke(*args)
        assert result.exit_code == 2, result.output
        (line,) = result.stderr.splitlines()
        assert line.startswith(f"homebench: error: {run_dir / name}: "), line


#: Values of the wrong type in the resolved config and the environment, by file and key.
WRONG_TYPES = {
    ("config.resolved.json", "methods"): 5,
    ("config.resolved.json", "databases"): [1, 2],
    ("config.resolved.json", "goals"): {"x": 1},
    ("config.resolved.json", "name"): 5,
    ("config.resolved.json", "kind"): [1],
    ("config.resolved.json", "conditions"): "some",
    ("config.resolved.json", "currents"): 5,
    ("config.resolved.json", "rotate_current"): [],
    ("config.resolved.json", "metrics"): {"ahc": 3},
    ("environment.json", "databases"): 5,
    ("environment.json", "versions"): {"numpy": 2},
    ("environment.json", "distributions"): 5,
    ("environment.json", "git"): 5,
    ("environment.json", "command"): "homebench run",
}
#: The commands that read a run folder.
READERS = [
    ["report", "--format", "md", "--no-progress"],
    ["leaderboard"],
    ["findings"],
    ["compare", "--label", "a", "--label", "b"],
]


@pytest.mark.parametrize(
    ("name", "key"), list(WRONG_TYPES), ids=[f"{n}:{k}" for n, k in WRONG_TYPES]
)
def test_a_record_of_the_wrong_types_is_one_line_naming_its_file_and_key(
    run_dir: Path, name: str, key: str
) -> None:
    """Each of these crashed report or leaderboard, or passed without a word."""
    path = run_dir / name
    record = json.loads(path.read_text())
    path.write_text(json.dumps({**record, key: WRONG_TYPES[name, key]}))
    for command, *options in READERS:
        folders = [str(run_dir)] * (2 if command == "compare" else 1)
        result = _invoke(command, *folders, *options)
        assert result.exit_code == 2, (command, result.output)
        (line,) = result.stderr.splitlines()
        assert line.startswith(f"homebench: error: {path}: {key}"), (command, line)


def test_a_failure_record_of_the_wrong_shape_is_no_record(run_dir: Path, tmp_path: Path) -> None:
    victim = sorted((run_dir / "jobs").glob("*.json"))[0]
    key = victim.stem
    victim.unlink()
    failure = {"kind": "home", "key": key, "job": "x", "cause": "y", "attempts": "a"}
    (run_dir / "failures").mkdir()
    (run_dir / "failures" / f"{key}.json").write_text(json.dumps(failure))
    result = _rerun(tmp_path)
    assert result.exit_code == 0, result.output
    assert "1 job(s) computed, 1 reused" in result.stdout
