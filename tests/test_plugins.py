"""Plugins load lazily: a broken installed plugin breaks only what needs it, in one line."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import arena_config, run_config
from plugins import install_plugin

from homebench.cli import main

BROKEN = 'raise ImportError("libfoo.so.1: cannot open shared object file")\n'


def test_a_broken_plugin_breaks_only_what_needs_it(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, source=BROKEN)
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest))
    assert result.exit_code == 0, result.output

    listing = CliRunner().invoke(main, ["methods"])
    assert listing.exit_code == 0, listing.output
    assert listing.stdout.startswith("alv ")
    broken = [line for line in listing.output.splitlines() if line.startswith(plugin.method)]
    assert len(broken) == 1
    assert f"{plugin.distribution} 1.0" in broken[0]
    assert "ImportError: libfoo.so.1" in broken[0]

    config = arena_config(tmp_path, arena_manifest, methods=[{"method": plugin.method}])
    result = run_config(tmp_path, config)
    assert result.exit_code == 2
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert f"distribution {plugin.distribution} 1.0" in result.stderr
    assert "ImportError: libfoo.so.1" in result.stderr


def test_an_entry_point_must_name_a_method_of_its_name(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = "from dataclasses import dataclass\n\n@dataclass(frozen=True)\nclass Faulty:\n"
    source += "    name = 'someone-else'\n    image_kind = 'unfolded'\n"
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, source=source)
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": plugin.method}])
    result = run_config(tmp_path, config)
    assert result.exit_code == 2
    assert "'someone-else'" in result.stderr and plugin.distribution in result.stderr
