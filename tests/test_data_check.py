"""homebench data check: a hand-written manifest held against its images.

The panoramas are the user's database of tests/vardy_layout.py (5 x 7 positions, heading 90,
clockwise PGM panoramas with azimuth 0 at column 100, a manifest typed as YAML); the wrong
manifests are copies of it with one value changed, as a user's mistake. The raw images are a
small generated world's (384 x 288, taken facing +y) under the user's own file names, with a
manifest typed likewise.

Tolerances: on full generated grids data check's azimuth offsets are within 0.7 deg of the
truth and its centres within 0.1 px (homebench.data.check); on these 5 x 7 grids (58 pairs)
the zero column is held to 1.5 columns (1.5 deg), a sixtieth of the 90-column error it
corrects, and the centre to 1 px of the 6 px error.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from vardy_layout import ZERO_COLUMN, write_database

from homebench.cli import EXIT_CHECK, main
from homebench.data.generate import generate
from homebench.data.synth.spec import GridSpec, RawImageSpec, WorldSpec
from homebench.fileio import read_grey

#: The raw world: 5 x 7 positions, every image facing +y; the mirror centred in the image,
#: azimuth growing clockwise from image angle 90 deg (the spec's defaults).
RAW_SPEC = WorldSpec(
    heading_deg=90.0,
    grid=GridSpec(shape=(5, 7)),
    raw=RawImageSpec(width=384, height=288, inner_radius=12.0, outer_radius=135.0),
)
CENTRE = (191.5, 143.5)

RAW_MANIFEST = """\
schema: 1
name: our-camera
grid: {{shape: [5, 7], spacing: 0.3, origin: [{x0}, {y0}]}}
heading_deg: 90
images:
  raw:
    folder: camera
    pattern: "shot-{{x}}-{{y}}.png"
    size: [384, 288]
    catadioptric:
      centre: [{u}, {v}]
      radii: [12, 135]
      elevations_deg: [-50, 45]
      direction: cw
      zero_angle_deg: 90
"""


@pytest.fixture(scope="module")
def panoramas(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The user's panorama database; its manifest's path."""
    return write_database(tmp_path_factory.mktemp("our-room"))


def _edited(manifest: Path, name: str, old: str, new: str) -> Path:
    """A copy of ``manifest`` beside it, ``old`` replaced by ``new``."""
    text = manifest.read_text()
    assert text.count(old) == 1
    path = manifest.with_name(name)
    path.write_text(text.replace(old, new))
    return path


def _check(manifest: Path) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["data", "check", str(manifest)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    return result.exit_code, result.stdout


def _fixes(out: str) -> str:
    """The corrections data check asks for."""
    return out.split("correct it:")[1]


@pytest.mark.slow  # CI time: docs/tutorials/own-grid.md checks a right manifest in a process
def test_a_right_manifest_passes_in_a_real_process(panoramas: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "data", "check", str(panoramas)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith(f"our-room-original ({panoramas}): images in {panoramas.parent}")
    assert re.search(r"direction\s+manifest cw\s+images cw\s+agrees", done.stdout)
    assert done.stdout.endswith("the manifest agrees with the images\n")


def test_a_flipped_direction_is_caught_and_corrected(panoramas: Path) -> None:
    code, out = _check(_edited(panoramas, "ccw.yaml", "direction: cw", "direction: ccw"))
    assert code == EXIT_CHECK, out
    assert "set images.unfolded.panorama.direction: cw (manifest: ccw)" in _fixes(out)
    assert "zero_column" not in _fixes(out)  # the zero column was right


def test_a_zero_column_90_degrees_off_is_caught_and_corrected(panoramas: Path) -> None:
    wrong = ZERO_COLUMN + 90
    code, out = _check(
        _edited(panoramas, "zero.yaml", f"zero_column: {ZERO_COLUMN}", f"zero_column: {wrong}")
    )
    assert code == EXIT_CHECK, out
    fix = re.search(
        r"set images\.unfolded\.panorama\.zero_column: ([\d.]+) \(manifest: ([\d.]+)\)", out
    )
    assert fix, out
    assert abs(float(fix[1]) - ZERO_COLUMN) <= 1.5 and float(fix[2]) == wrong
    assert "direction" not in _fixes(out)


def test_a_mirror_centre_6_px_off_is_caught_and_corrected(tmp_path: Path) -> None:
    world = generate(RAW_SPEC)
    (tmp_path / "camera").mkdir()
    for i, j in RAW_SPEC.to_grid().indices():
        image = read_grey(world / "raw" / f"{i}_{j}.png")
        assert cv2.imwrite(str(tmp_path / "camera" / f"shot-{i}-{j}.png"), image)
    x0, y0 = RAW_SPEC.to_grid().origin
    manifest = tmp_path / "manifest.yaml"
    manifest.write_text(RAW_MANIFEST.format(x0=x0, y0=y0, u=CENTRE[0] + 6, v=CENTRE[1]))
    code, out = _check(manifest)
    assert code == EXIT_CHECK, out
    fix = re.search(r"set images\.raw\.catadioptric\.centre: \[([\d.]+), ([\d.]+)\]", out)
    assert fix, out
    assert np.hypot(float(fix[1]) - CENTRE[0], float(fix[2]) - CENTRE[1]) <= 1.0
    assert "(manifest: [197.5, 143.5])" in _fixes(out)
    # measured about the rim's centre, the azimuths and the horizon agree with the manifest
    assert all(key not in _fixes(out) for key in ("direction", "zero_angle", "elevations"))


def test_files_that_are_not_the_positions_their_names_say_tell_no_direction(
    panoramas: Path, tmp_path: Path
) -> None:
    files = sorted((panoramas.parent / "panoramas").iterdir())
    shuffled = np.random.default_rng(0).permutation(len(files))
    (tmp_path / "panoramas").mkdir()
    for source, k in zip(files, shuffled, strict=True):
        (tmp_path / "panoramas" / files[k].name).write_bytes(source.read_bytes())
    manifest = tmp_path / "manifest.yaml"
    manifest.write_text(panoramas.read_text())
    code, out = _check(manifest)
    assert code == EXIT_CHECK, out
    assert "images.unfolded.panorama.direction: the images tell no direction" in _fixes(out)


def test_a_grid_without_neighbours_along_y_is_an_error(panoramas: Path) -> None:
    manifest = _edited(panoramas, "row.yaml", "shape: [5, 7]", "shape: [5, 1]")
    result = CliRunner().invoke(main, ["data", "check", str(manifest)])
    assert result.exit_code == 2
    assert "homes between neighbours along x and along y; its grid is 5 x 1" in result.stderr
