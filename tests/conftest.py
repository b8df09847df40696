"""Shared test set-up: generated worlds go to a per-session cache, never the user's."""

from __future__ import annotations

import math
import resource
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner, Result


@pytest.fixture(scope="session", autouse=True)
def _session_data_dir(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Point HOMEBENCH_DATA at a temporary folder shared by the whole test session."""
    patcher = pytest.MonkeyPatch()
    patcher.setenv("HOMEBENCH_DATA", str(tmp_path_factory.mktemp("homebench-data")))
    yield
    patcher.undo()


@pytest.fixture(autouse=True)
def _close_figures() -> Iterator[None]:
    """Close the figures a test left open (matplotlib keeps every pyplot figure until then),
    without importing pyplot into tests that never drew."""
    yield
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close("all")


ARENA_GRID = {"shape": [4, 5], "spacing": 0.3, "origin": [-0.45, -0.6]}
ARENA_HEADING_DEG = 30.0


def write_arena_database(folder: Path) -> Path:
    """A user-made unfolded-only grid database of the analytic arena; returns its manifest.

    4 x 5 positions 0.3 m apart around the arena centre, every image taken at heading 30 deg.
    """
    from synthetic_panorama import GEOMETRY, render

    from homebench.fileio import write_png
    from homebench.geometry import Grid

    grid = Grid(tuple(ARENA_GRID["shape"]), ARENA_GRID["spacing"], tuple(ARENA_GRID["origin"]))
    (folder / "pano").mkdir(parents=True, exist_ok=True)
    for i, j in grid.indices():
        write_png(
            folder / "pano" / f"p{i}-{j}.png", render(grid.pose(i, j, math.radians(30))).image
        )
    manifest = {
        "schema": 1,
        "name": "arena",
        "description": "analytic circular arena (tests)",
        "grid": ARENA_GRID,
        "heading_deg": ARENA_HEADING_DEG,
        "images": {
            "unfolded": {
                "folder": "pano",
                "pattern": "p{x}-{y}.png",
                "extensions": ["png"],
                "size": [GEOMETRY.width, GEOMETRY.height],
                "panorama": {
                    "elevation_top_deg": math.degrees(GEOMETRY.elevation_top),
                    "elevation_bottom_deg": math.degrees(GEOMETRY.elevation_bottom),
                },
            }
        },
    }
    path = folder / "manifest.yaml"
    path.write_text(yaml.safe_dump(manifest, sort_keys=False))
    return path


@pytest.fixture(scope="session")
def arena_manifest(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_arena_database(tmp_path_factory.mktemp("arena"))


def arena_config(folder: Path, manifest: Path, **changes: object) -> dict:
    """A run config over the arena database: two goals, warping and a coarse warping entry,
    results in ``folder/run``; ``changes`` replace top-level keys."""
    return {
        "name": "arena-run",
        "output": str(folder / "run"),
        "databases": {"arena": str(manifest)},
        "conditions": ["arena-arena"],
        "goals": [[1, 2], [2, 3]],
        "methods": [
            {"method": "warping"},
            {"method": "warping", "label": "warping-coarse", "params": {"n_rho": 8}},
        ],
        **changes,
    }


def run_config(folder: Path, config: dict, *options: str, report: bool = False) -> Result:
    """Write ``config`` to ``folder/config.yaml`` and `homebench run` it as a user would (no
    progress bars; no PDF unless ``report``); the click result."""
    from homebench.cli import main

    path = folder / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    flags = ["--no-progress", *([] if report else ["--no-report"]), *options]
    return CliRunner().invoke(main, ["run", str(path), *flags])


def homebench_limited(*args: str) -> subprocess.CompletedProcess[str]:
    """`homebench args` in a real process with 2 GiB of address space and 60 s at most."""

    def limit_memory() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    return subprocess.run(
        [sys.executable, "-m", "homebench", *args],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=limit_memory,
        check=False,
    )
