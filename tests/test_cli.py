"""The command line as a user meets it: help, version, data commands, exit codes."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from homebench import __version__
from homebench.cli import main


def _invoke(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


def _commands(group: click.Group, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    found = [prefix]
    for name, command in group.commands.items():
        if isinstance(command, click.Group):
            found += _commands(command, (*prefix, name))
        else:
            found.append((*prefix, name))
    return found


@pytest.mark.parametrize("command", _commands(main))
def test_every_command_has_help(command: tuple[str, ...]) -> None:
    code, out, _ = _invoke(*command, "--help")
    assert code == 0 and "Usage:" in out


def test_version_in_a_real_process() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "homebench", "--version"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0
    assert __version__ in result.stdout


def test_methods_lists_parameters_and_defaults() -> None:
    code, out, _ = _invoke("methods")
    assert code == 0
    assert "warping " in out and "min-warping " in out
    code, out, _ = _invoke("methods", "warping")
    assert code == 0
    assert "warping (unfolded images)" in out and "n_rho = 20" in out


def test_data_list_shows_shipped_manifests() -> None:
    code, out, _ = _invoke("data", "list")
    assert code == 0
    for name in ("bielefeld-original", "bielefeld-day", "synth-original", "synth-winlit"):
        assert name in out


def test_data_verify_and_show_on_a_user_database(arena_manifest: Path, tmp_path: Path) -> None:
    code, out, err = _invoke("data", "verify", str(arena_manifest))
    assert code == 0, err
    assert f"arena ({arena_manifest}): 20 images OK" in out
    code, out, err = _invoke("data", "show", str(arena_manifest), "--out", str(tmp_path))
    assert code == 0, err
    sheet = Path(out.strip())
    assert sheet.is_file() and sheet.stat().st_size > 50_000


def test_unknown_database_is_one_line_exit_2() -> None:
    code, _, err = _invoke("data", "verify", "no-such-database")
    assert code == 2
    assert err.count("\n") == 1 and "unknown database 'no-such-database'" in err


def test_real_set_without_a_copy_says_how_to_point_at_one(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("HOMEBENCH_BIELEFELD_ORIGINAL", raising=False)
    code, _, err = _invoke("data", "verify", "bielefeld-original")
    assert code == 2
    assert "HOMEBENCH_BIELEFELD_ORIGINAL" in err and "--path" in err


def test_a_crash_is_exit_1_without_traceback_unless_debug(monkeypatch: pytest.MonkeyPatch) -> None:
    def explode() -> None:
        raise RuntimeError("boom")

    monkeypatch.setattr("homebench.data.catalog.list_databases", explode)
    code, _, err = _invoke("data", "list")
    assert code == 1
    assert "RuntimeError: boom" in err and "Traceback" not in err
    result = CliRunner().invoke(main, ["--debug", "data", "list"])
    assert isinstance(result.exception, RuntimeError)


def test_data_generate_a_manifest_and_a_variant_then_verify(tmp_path: Path) -> None:
    from homebench.data.generate import manifest_for_spec
    from homebench.data.synth.spec import WorldSpec

    spec = WorldSpec.model_validate(
        {"grid": {"shape": [2, 2]}, "unfolded": {"width": 90}, "raw": {"width": 96, "height": 72,
         "inner_radius": 4, "outer_radius": 34}}
    )  # fmt: skip
    manifest = tmp_path / "tiny-original.yaml"
    manifest.write_text(manifest_for_spec(spec, "tiny-original").to_yaml())
    code, out, err = _invoke("data", "generate", str(manifest), "--out", str(tmp_path / "a"))
    assert code == 0, err
    assert out.strip().endswith(f"; 8 images (raw 96 x 72, unfolded 90 x 24) in {tmp_path / 'a'}")
    code, out, err = _invoke(
        "data", "generate", str(manifest), "--variant", "day", "--out", str(tmp_path / "day")
    )
    assert code == 0, err
    code, out, err = _invoke("data", "verify", str(tmp_path / "day"))
    assert code == 0 and f"tiny-day ({tmp_path / 'day'}): 8 images OK" in out, err
    code, _, err = _invoke("data", "generate", str(manifest), "--variant", "dusk")
    assert code == 2 and "unknown variant 'dusk'" in err
