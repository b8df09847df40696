"""``homebench data check`` on posed images: a Brains on Board route written the way BoB's Ant
World tools write one (tests/bob_folders.py: compass headings by BoB's route formula, the
camera facing the way it travels, columns and rows as BoB's renderer lays them out), with the
right conventions and with each of them planted wrong in its ``homebench.yaml``.

The route: east 1.2 m, a left quarter turn of radius 0.6 m, north 1.2 m, an image every 5 cm
(68 poses) in the analytic arena. Measured: with the right conventions the images fit with a
mean AE of 2.2 deg (the mirrored direction 33.7, the other heading sense 61-76); the headings
follow the direction of travel to a median 0.7 deg, their zero 89.3 deg (the central
differences of a route sampled along a bend), held to 5 deg.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from bob_folders import bend_points, write_route
from click.testing import CliRunner

from homebench.cli import EXIT_CHECK, main
from homebench.data.bob import open_bob
from homebench.geometry import angle_diff, home_direction
from homebench.methods import registry


@pytest.fixture(scope="module")
def bend(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_route(tmp_path_factory.mktemp("posed") / "bend", bend_points())


def _check(folder: Path) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, ["data", "check", str(folder)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    return result.exit_code, result.stdout, result.stderr


def _planted(bend: Path, tmp_path: Path, homebench_yaml: str) -> Path:
    folder = tmp_path / "bend"
    shutil.copytree(bend, folder)
    (folder / "homebench.yaml").write_text(homebench_yaml)
    return folder


def test_bobs_own_conventions_pass_in_a_real_process(bend: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "data", "check", str(bend)],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout
    assert "a route of 68 poses, 3.34 m long" in out
    assert "they follow it: the recorder faced the way it moved" in out
    stated = re.search(r"as stated: mean AE ([\d.]+) deg", out)
    assert stated is not None and float(stated[1]) < 5.0, out
    for what in ("heading sense", "heading zero", "direction", "zero column", "horizon"):
        assert re.search(rf"  {what} .* agrees", out), (what, out)


@pytest.mark.parametrize(
    ("planted", "fix"),
    [
        ("headings: {direction: ccw}", r"set headings\.direction: cw \(manifest: ccw\)"),
        (
            "headings: {zero_deg: 0}",
            r"set headings\.zero_deg: (8[5-9]|9[0-5])\.?\d* \(manifest: 0\)",
        ),
        (
            "images: {unfolded: {panorama: {direction: ccw}}}",
            r"set images\.unfolded\.panorama\.direction: cw \(manifest: ccw\)",
        ),
        (
            "images: {unfolded: {panorama: {zero_column: 100}}}",
            r"set images\.unfolded\.panorama\.zero_column: 14[2-5]\.\d \(manifest: 100\.0\)",
        ),
    ],
    ids=["heading sense", "heading zero", "column direction", "column zero"],
)
def test_each_planted_convention_error_is_found_and_only_it(
    bend: Path, tmp_path: Path, planted: str, fix: str
) -> None:
    code, out, _ = _check(_planted(bend, tmp_path, planted + "\n"))
    assert code == EXIT_CHECK, out
    fixes = out.split("correct it:")[1].strip().splitlines()
    assert len(fixes) == 1 and re.fullmatch(fix, fixes[0].strip()), out


def test_a_camera_that_does_not_turn_leaves_the_heading_zero_to_the_images(
    tmp_path: Path,
) -> None:
    """Every image at compass heading 30 while the route bends: the headings do not follow
    travel, so their zero is not checked, and a zero column planted 45 deg off may as well be
    a heading zero 45 deg off (the alternative)."""
    folder = write_route(tmp_path / "fixed", bend_points(), fixed_heading_deg=30.0)
    code, out, _ = _check(folder)
    assert code == 0, out
    assert "they do not follow it" in out and "heading zero" in out
    assert re.search(r"heading zero .* not checked: the headings do not follow", out), out
    (folder / "homebench.yaml").write_text("images: {unfolded: {panorama: {zero_column: 107.5}}}\n")
    code, out, _ = _check(folder)
    assert code == EXIT_CHECK, out
    fixes = out.split("correct it:")[1]
    assert re.search(r"zero_column: 14[2-5]\.\d \(manifest: 107\.5\), or headings\.zero_deg", fixes)


def test_data_show_warns_when_the_headings_cross_the_path(bend: Path, tmp_path: Path) -> None:
    shown = CliRunner().invoke(main, ["data", "show", str(bend), "--out", str(tmp_path / "a")])
    assert shown.exit_code == 0 and "warning" not in shown.stderr, shown.output
    folder = _planted(bend, tmp_path, "headings: {zero_deg: 0, direction: ccw}\n")
    shown = CliRunner().invoke(main, ["data", "show", str(folder), "--out", str(tmp_path / "b")])
    assert shown.exit_code == 0, shown.output
    warning = "the headings as read differ from the direction of travel by more than 45 deg"
    assert warning in shown.stderr and "`homebench data check`" in shown.stderr


def test_along_a_straight_stretch_home_lies_straight_behind_and_min_warping_finds_it(
    bend: Path,
) -> None:
    """On the route's first stretch (east, images 0-23, 5 cm apart) the true home direction
    from image k to image k - 4, read with BoB's conventions, is straight behind (pi), and
    min-warping with its defaults homes there: mean AE 2.6 deg, at most 6.3 (its search step
    is 3.75 deg, 96 a turn) over 18 pairs, held to 4 and 10."""
    db = open_bob(bend)
    method = registry.create("min-warping")
    errors = []
    for k in range(6, 24):
        truth = float(home_direction(db.xy[k], db.xy[k - 4], math.radians(db.heading_deg[k])))
        assert abs(angle_diff(truth, math.pi)) < 1e-9
        estimate = method.home(method.describe(db.view(k)), method.describe(db.view(k - 4)))
        errors.append(math.degrees(abs(angle_diff(estimate.angle, truth))))
    assert np.mean(errors) < 4.0 and max(errors) < 10.0, errors
