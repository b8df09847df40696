"""Grids whose labels are not their positions: ``grid.order`` reads them, ``data check`` finds
the order the images show.

- Brains on Board grid folders written the way BoB's Ant World tools write them
  (tests/bob_folders.py's ``write_recorder_grid``: image k rendered at the k-th position of
  ``GridRecorder::getPositions()`` and labelled as ``GridRecorder::record()`` labels it), on a
  square grid (where BoB's order is a transposition, which a mirrored direction fits as well)
  and a 5 x 4 one (where it scrambles the labels and nothing else fits).
- A database in Vardy's layout (tests/vardy_layout.py's hand-written one) whose files are
  named transposed, read with ``grid: {order: transposed}`` in its manifest.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from bob_folders import write_recorder_grid
from click.testing import CliRunner
from vardy_layout import write_database

from homebench.cli import EXIT_CHECK, main
from homebench.data.catalog import resolve
from homebench.geometry import angular_error, home_direction
from homebench.methods import registry


@pytest.fixture(scope="module")
def square(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_recorder_grid(tmp_path_factory.mktemp("order") / "square", (5, 5))


@pytest.fixture(scope="module")
def oblong(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_recorder_grid(tmp_path_factory.mktemp("order") / "oblong", (5, 4))


def _check(database: Path) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["data", "check", str(database)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    return result.exit_code, result.stdout


def _mean_ae_deg(database: Path, pairs: list[tuple[tuple[int, int], tuple[int, int]]]) -> float:
    """min-warping's mean AE (deg) over neighbour ``pairs`` of the grid as read."""
    db, method = resolve(database), registry.create("min-warping")
    errors = []
    for current, goal in pairs:
        estimate = method.home(method.describe(db.view(*current, "unfolded")),
                               method.describe(db.view(*goal, "unfolded"))).angle  # fmt: skip
        c, g = db.pose(*current), db.pose(*goal)
        truth = home_direction(c.xy, g.xy, c.heading)
        errors.append(math.degrees(angular_error(estimate, truth)) if estimate is not None else 180)
    return sum(errors) / len(errors)


NEIGHBOURS = [((1, 1), (2, 1)), ((2, 2), (2, 3)), ((3, 1), (3, 0)), ((2, 2), (1, 2))]


def test_a_square_recorder_grid_is_found_transposed_with_the_mirror_as_alternative(
    square: Path, tmp_path: Path
) -> None:
    code, out = _check(square)
    assert code == EXIT_CHECK, out
    fix = "set grid.order: bob-recorder (manifest: as-written), or "
    assert fix + "images.unfolded.panorama.direction: ccw" in out, out
    assert "zero_column" not in out.split("correct it:")[1]
    assert _mean_ae_deg(square, NEIGHBOURS) > 45.0  # as written, homing goes wrong

    folder = tmp_path / "fixed"
    shutil.copytree(square, folder)
    (folder / "homebench.yaml").write_text("grid: {order: bob-recorder}\n")
    code, out = _check(folder)
    assert code == 0, out
    assert _mean_ae_deg(folder, NEIGHBOURS) < 6.0


def test_an_oblong_recorder_grid_is_found_in_bobs_order_alone(oblong: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "data", "check", str(oblong)],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == EXIT_CHECK, done.stdout + done.stderr
    fixes = done.stdout.split("correct it:")[1].strip().splitlines()
    assert fixes == ["set grid.order: bob-recorder (manifest: as-written)"], done.stdout
    assert "grid.order: bob-recorder" in done.stderr  # the note on BoB's recorder


def test_a_config_entry_reads_the_order(oblong: Path, tmp_path: Path) -> None:
    """``grid: {order: ...}`` of a run config's database entry reads the folder in that order:
    the image labelled (a, b) is the k-th recorded, k = b nx + a, taken at (k // ny, k % ny)."""
    config = tmp_path / "run.yaml"
    config.write_text(
        "name: ordered\n"
        f"output: {tmp_path / 'run'}\n"
        f"databases: {{g: {{name: '{oblong}', grid: {{order: bob-recorder}}}}}}\n"
        "conditions: [g-g]\ngoals: [[2, 1]]\nmethods: [{method: min-warping}]\n"
    )
    result = CliRunner().invoke(main, ["run", str(config), "--no-progress", "--no-report"])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    assert len(table) == 19 and table["ae_rad"].max() < math.radians(10.0), table


@pytest.fixture(scope="module")
def transposed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The Vardy-layout database (5 x 7 positions) with each file named by its position's
    transpose: pano_X{j}_Y{i} holds the image taken at (i, j); its manifest as the user would
    write it without knowing (labels spanning 7 x 5, as written)."""
    source = write_database(tmp_path_factory.mktemp("vardy") / "source")
    folder = tmp_path_factory.mktemp("vardy") / "transposed"
    (folder / "panoramas").mkdir(parents=True)
    for path in (source.parent / "panoramas").iterdir():
        i, j = (int(v) for v in re.findall(r"\d+", path.name))
        (folder / "panoramas" / f"pano_X{j:02d}_Y{i:02d}.pgm").write_bytes(path.read_bytes())
    text = source.read_text().replace("shape: [5, 7]", "shape: [7, 5]")
    (folder / "manifest.yaml").write_text(text)
    return folder / "manifest.yaml"


def test_a_manifest_key_reads_a_transposed_vardy_grid(transposed: Path, tmp_path: Path) -> None:
    code, out = _check(transposed)  # a mirrored direction fits as well: the alternative
    assert code == EXIT_CHECK, out
    assert "or grid.order: transposed" in out.split("correct it:")[1], out

    stated = tmp_path / "manifest.yaml"
    stated.write_text(
        transposed.read_text().replace(
            "origin: [0.0, 0.0]}", "origin: [0.0, 0.0], order: transposed}"
        )
    )
    shutil.copytree(transposed.parent / "panoramas", tmp_path / "panoramas")
    db = resolve(stated)
    assert db.grid.shape == (5, 7)  # positions; the files' labels span 7 x 5
    assert db.path(1, 4, "unfolded").name == "pano_X04_Y01.pgm"
    assert db.heading(1, 4) == pytest.approx(math.radians(90.0))
    code, out = _check(stated)
    assert code == 0, out
    verified = CliRunner().invoke(main, ["data", "verify", str(stated)])
    assert verified.exit_code == 0, verified.output
