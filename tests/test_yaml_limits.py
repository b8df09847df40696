"""YAML input has limits: size, file kind, nesting, alias expansion; every failure is one line
naming the file (and line), exit 2, in bounded time (issue 12)."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import homebench_limited

from homebench import yamlio
from homebench.cli import main
from homebench.data.catalog import SHIPPED_MANIFESTS
from homebench.data.manifest import load_manifest

CONFIGS = Path(__file__).resolve().parent.parent / "configs"


def _run(path: Path) -> tuple[int, str]:
    """`homebench run path` in this process; (exit code, stderr)."""
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    return result.exit_code, result.stderr


def _assert_one_line(err: str, *parts: str) -> None:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("homebench: error: "), err
    for part in parts:
        assert part in lines[0], err


def _alias_bomb(levels: int, fan_out: int) -> str:
    """The "billion laughs": each anchor a list of ``fan_out`` aliases of the one before."""
    lines = ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    for k in range(1, levels + 1):
        lines.append(f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * fan_out) + "]")
    return "\n".join(lines) + "\n"


def test_dev_zero_and_a_fifo_are_refused_before_reading(tmp_path: Path) -> None:
    fifo = tmp_path / "config.yaml"
    os.mkfifo(fifo)  # nobody ever writes to it: reading would wait for ever
    for path in ("/dev/zero", str(fifo)):
        start = time.monotonic()
        done = homebench_limited("run", path)
        assert done.returncode == 2, done.stderr
        _assert_one_line(done.stderr, path, "not a regular file")
        assert time.monotonic() - start < 30


def test_a_folder_is_refused(tmp_path: Path) -> None:
    code, err = _run(tmp_path)
    assert code == 2
    _assert_one_line(err, str(tmp_path), "not a regular file")


def test_a_file_over_the_size_cap_is_refused_before_parsing(tmp_path: Path) -> None:
    path = tmp_path / "big.yaml"
    path.write_text("# padding\n" * (yamlio.MAX_YAML_BYTES // 10 + 1))
    code, err = _run(path)
    assert code == 2
    _assert_one_line(err, str(path), "larger than the 4 MiB")


def test_an_alias_bomb_is_stopped_at_once(tmp_path: Path) -> None:
    path = tmp_path / "bomb.yaml"
    path.write_text(_alias_bomb(levels=9, fan_out=9))  # 9**10 strings once expanded
    start = time.monotonic()
    code, err = _run(path)
    assert time.monotonic() - start < 5
    assert code == 2
    _assert_one_line(err, f"{path}:", "aliases")


def test_a_shared_subtree_is_visited_once(tmp_path: Path) -> None:
    """Aliases under the expansion cap are fine: the checks do not revisit shared nodes."""
    text = _alias_bomb(levels=3, fan_out=9) + "name: shared\n"
    path = tmp_path / "shared.yaml"
    path.write_text(text)
    assert yamlio.read_yaml(path).data["name"] == "shared"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a: &a [1, *a]\n", "recursive alias"),
        ("a: &a {b: *a}\n", "recursive alias"),
        ("? [a, b]\n: 1\n", "a key must be"),
        ("? {a: 1}\n: 1\n", "a key must be"),
        ("a: " + "[" * 3000 + "]" * 3000 + "\n", "nested deeper than"),
        ("a:\n" + "".join("  " * k + f"k{k}:\n" for k in range(1, 200)), "nested deeper than"),
        ("a: " + "9" * 5000 + "\n", "cannot read"),
        ("a: 2020-13-45\n", "cannot read"),
        ("a: !!python/object:os.system x\n", "YAML"),
        ("a: \x07\n", "YAML"),
    ],
)
def test_malformed_yaml_is_one_line_and_exit_2(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    code, err = _run(path)
    assert code == 2
    _assert_one_line(err, str(path), message)


def test_the_same_limits_guard_manifests(tmp_path: Path) -> None:
    path = tmp_path / "manifest.yaml"
    path.write_text(_alias_bomb(levels=9, fan_out=9))
    result = CliRunner().invoke(main, ["data", "verify", str(path)])
    assert result.exit_code == 2
    _assert_one_line(result.stderr, str(path), "aliases")


def test_many_validation_errors_are_summed_up(tmp_path: Path) -> None:
    path = tmp_path / "config.yaml"
    path.write_text("".join(f"unknown_{k}: 1\n" for k in range(500)))
    code, err = _run(path)
    assert code == 2
    assert len(err.splitlines()) <= yamlio.MAX_REPORTED_ERRORS + 1
    assert "more problems" in err.splitlines()[-1]


def test_shipped_files_fit_the_caps_with_room(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every shipped manifest and config loads with caps 20 times smaller than the real ones."""
    monkeypatch.setattr(yamlio, "MAX_YAML_BYTES", yamlio.MAX_YAML_BYTES // 20)
    monkeypatch.setattr(yamlio, "MAX_YAML_NODES", yamlio.MAX_YAML_NODES // 20)
    monkeypatch.setattr(yamlio, "MAX_YAML_DEPTH", yamlio.MAX_YAML_DEPTH // 4)
    manifests = sorted(SHIPPED_MANIFESTS.glob("*.yaml"))
    configs = sorted(CONFIGS.glob("*.yaml"))
    assert len(manifests) >= 10 and len(configs) >= 5
    for path in manifests:
        assert load_manifest(path).name == path.stem
    for path in configs:
        assert yamlio.read_yaml(path).data
