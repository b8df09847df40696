"""Brains on Board folders from someone else: every bad input is one line naming the file (and
line), exit 2, nothing executed; raw images unwrapped as BoB unwraps them; OpenCV's YAML."""

from __future__ import annotations

import math
import os
import re
import shutil
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from bob_folders import ROUTE_METADATA, route_poses, write_grid, write_route
from click.testing import CliRunner

from homebench.cli import main
from homebench.data.bob import entries, open_bob
from homebench.data.bob.camera import from_unwrapper
from homebench.data.bob.filestorage import as_yaml
from homebench.data.bob.metadata import Unwrapper
from homebench.data.grid_fit import fit_grid
from homebench.errors import ConfigError, DataError


@pytest.fixture(scope="module")
def sources(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    base = tmp_path_factory.mktemp("bob-sources")
    return {"grid": write_grid(base / "grid"), "route": write_route(base / "route")}


def _edit(folder: Path, name: str, old: str, new: str, count: int = 1) -> None:
    """Replace ``old`` by ``new`` (``count`` times) in ``folder/name``."""
    path = folder / name
    text = path.read_text()
    assert old in text, (name, old)
    path.write_text(text.replace(old, new, count))


def _entries(folder: Path, old: str, new: str, count: int = 1) -> None:
    _edit(folder, "database_entries.csv", old, new, count)


def _metadata(folder: Path, text: str) -> None:
    (folder / "database_metadata.yaml").write_text(text)


def _drop_row(folder: Path, name: str) -> None:
    path = folder / "database_entries.csv"
    path.write_text("".join(line for line in path.open() if name not in line))


def _link_out(folder: Path, name: str) -> None:
    """Move ``folder/name`` out of the folder and leave a symbolic link to it in its place."""
    outside = folder.parent / f"outside-{name}"
    shutil.move(folder / name, outside)
    (folder / name).symlink_to(outside)


def _link_folder_out(folder: Path) -> None:
    """List image00003.png in ``sub/``, a symbolic link to a folder outside."""
    elsewhere = folder.parent / "elsewhere"
    elsewhere.mkdir()
    shutil.move(folder / "image00003.png", elsewhere / "image00003.png")
    (folder / "sub").symlink_to(elsewhere)
    _entries(folder, "image00003.png", "sub/image00003.png")


RAW_OVERRIDES = """\
images:
  raw:
    catadioptric: {centre: [10, 10], radii: [2, 9], elevations_deg: [-40, 40]}
"""


def _replace(path: Path, make: Callable[[Path], object]) -> None:
    """Put what ``make(path)`` makes in place of the file ``path``."""
    path.unlink()
    make(path)


def _rewrite(folder: Path, column: int, value: Callable[[str], str]) -> None:
    """Replace each row's value in ``column`` by ``value(old)``."""
    path = folder / "database_entries.csv"
    header, *rows = path.read_text().splitlines()
    lines = [header]
    for row in rows:
        cells = row.split(", ")
        cells[column] = value(cells[column])
        lines.append(", ".join(cells))
    path.write_text("\n".join(lines) + "\n")


def _scale_y(folder: Path) -> None:
    """Rows 1.5 times as far apart along y as along x."""
    _rewrite(folder, 1, lambda y: f"{(float(y) + 450) * 1.5 - 450:g}")


def _mirror_x(folder: Path) -> None:
    """Grid X counted from the other side: index i at the x of 4 - i."""
    _rewrite(folder, 7, lambda i: str(4 - int(i)))


ENTRIES = r"database_entries\.csv"
METADATA = r"database_metadata\.yaml"
BAD_INPUTS: dict[str, tuple[str, Callable[[Path], None], str]] = {
    "missing column": (
        "grid",
        lambda f: _entries(f, "Heading [degrees]", "Yaw [degrees]"),
        ENTRIES + r":1: no 'Heading \[degrees\]' column",
    ),
    "file name with ..": (
        "grid",
        lambda f: _entries(f, "image_-000600_-000450", "../image_-000600_-000450"),
        ENTRIES + r":\d+: Filename '\.\./image_.*' has an empty, '\.' or '\.\.' path component",
    ),
    "absolute file name": (
        "route",
        lambda f: _entries(f, "image00003.png", "/etc/passwd"),
        ENTRIES + r":4: Filename '/etc/passwd' has an empty",
    ),
    "backslash": (
        "route",
        lambda f: _entries(f, "image00003.png", "..\\image00003.png"),
        ENTRIES + r":4: Filename .* has a control character or a backslash",
    ),
    "not on a grid": (
        "grid",
        lambda f: _entries(f, "-300, 150, 10", "-180, 150, 10"),
        ENTRIES + r":\d+: grid position \(1, 2\) at \(-0\.180, 0\.150\) m lies 0\.1\d\d m off "
        r"the regular grid",
    ),
    "two spacings": (
        "grid",
        _scale_y,
        ENTRIES + r": the grid is 0\.3 m apart along x and 0\.45 m along y",
    ),
    "grid index falls as X grows": (
        "grid",
        _mirror_x,
        ENTRIES + r": the grid index along x grows as x falls",
    ),
    "unparsable metadata": (
        "grid",
        lambda f: _metadata(f, "%YAML:1.0\n---\nmetadata:\n   type: [grid\n"),
        METADATA + r":5:1: YAML syntax error",
    ),
    "a Python tag": (
        "grid",
        lambda f: _metadata(f, '%YAML:1.0\n---\nmetadata: !!python/object/apply:os.system ["x"]\n'),
        METADATA + r":3:11: YAML syntax error: could not determine a constructor",
    ),
    "metadata nested too deep": (
        "grid",
        lambda f: _metadata(f, "metadata: " + "[" * 100 + "]" * 100 + "\n"),
        METADATA + r":1:\d+: YAML nested deeper than 64 levels",
    ),
    "unknown type": (
        "grid",
        lambda f: _edit(f, "database_metadata.yaml", "type: grid", "type: mesh"),
        METADATA + r":\d+: metadata\.type: Input should be 'grid' or 'route'",
    ),
    "grid without grid columns": (
        "route",
        lambda f: _edit(f, "database_metadata.yaml", "type: route", "type: grid"),
        METADATA + r": type: grid, but .*database_entries\.csv has no Grid X",
    ),
    "a grid row twice": (
        "grid",
        lambda f: _entries(f, ", 1, 2, 0,", ", 1, 3, 0,"),
        ENTRIES + r":\d+: grid position \(1, 3\) again \(first on line \d+\)",
    ),
    "two layers": (
        "grid",
        lambda f: _entries(f, ", 0, 0, 0,", ", 0, 0, 1,"),
        ENTRIES + r": Grid Z takes 2 values \(0, 1\): homebench reads grids of one layer",
    ),
    "a huge grid index": (
        "grid",
        lambda f: _entries(f, ", 0, 0, 0,", ", 9999999, 0, 0,"),
        ENTRIES + r": Grid X, Grid Y span a 10000000 x 5 grid; at most 1,000,000",
    ),
    "not a grid index": (
        "grid",
        lambda f: _entries(f, ", 0, 0, 0,", ", -1, 0, 0,"),
        ENTRIES + r":\d+: Grid X '-1' is not a grid index",
    ),
    "wrong number of values": (
        "route",
        lambda f: _entries(f, ", image00002.png", ", image00002.png, 7"),
        ENTRIES + r":3: 6 values, but the header names 5 columns",
    ),
    "not a number": (
        "route",
        lambda f: _entries(f, "1000, 0,", "1OOO, 0,"),
        ENTRIES + r":2: X \[mm\] '1OOO' is not a number",
    ),
    "an absurd heading": (
        "route",
        lambda f: _entries(f, f", {route_poses()[0][2]:g}, image00001", ", 1e300, image00001"),
        ENTRIES + r":2: Heading \[degrees\] is 1e300: a heading is at most 1,000,000 degrees",
    ),
    "an infinite heading": (
        "route",
        lambda f: _entries(f, f", {route_poses()[0][2]:g}, image00001", ", inf, image00001"),
        ENTRIES + r":2: Heading \[degrees\] is inf: a position or heading is a finite number",
    ),
    "no row with a pose": (
        "route",
        lambda f: _rewrite(f, 3, lambda h: "nan"),
        ENTRIES + r": none of its 10 rows has both a position and a heading \(missing_poses: "
        r"skip\)",
    ),
    "a grid whose rows all lost their positions": (
        "grid",
        lambda f: (
            _rewrite(f, 0, lambda x: "nan"),
            (f / "homebench.yaml").write_text("missing_poses: interpolate\n"),
        ),
        ENTRIES + r": a grid of 0 recorded position\(s\) has no spacing",
    ),
    "an unknown missing_poses": (
        "route",
        lambda f: (f / "homebench.yaml").write_text("missing_poses: guess\n"),
        r"homebench\.yaml:1: missing_poses: Input should be 'skip' or 'interpolate'",
    ),
    "a grid size of 0": (
        "grid",
        lambda f: _edit(f, "database_metadata.yaml", "size: [ 5, 5, 1 ]", "size: [ 0, 5, 1 ]"),
        METADATA + r":\d+: metadata\.grid\.size\[0\]: Input should be greater than or equal to 1",
    ),
    "a video": (
        "route",
        lambda f: _entries(f, "Filename", "Frame"),
        ENTRIES + r":1: a video database \(a Frame column, no Filename\)",
    ),
    "a video named in the metadata": (
        "route",
        lambda f: _metadata(f, ROUTE_METADATA + "   videoFile: route.avi\n"),
        METADATA + r": a video database \(videoFile: route\.avi\)",
    ),
    "a missing image": (
        "route",
        lambda f: (f / "image00004.png").unlink(),
        r"route: 1 image\(s\) listed in database_entries\.csv are missing: image00004\.png",
    ),
    "an image that is a folder": (
        "route",
        lambda f: _replace(f / "image00004.png", Path.mkdir),
        r"route/image00004\.png: the image is a folder, not a file$",
    ),
    "an image that is a FIFO": (
        "route",
        lambda f: _replace(f / "image00004.png", os.mkfifo),
        r"route/image00004\.png: the image is a FIFO, not a file$",
    ),
    "an image that is a symbolic link loop": (
        "route",
        lambda f: _replace(f / "image00004.png", lambda p: p.symlink_to(p.name)),
        r"route/image00004\.png: cannot open the image \(Too many levels of symbolic links\)$",
    ),
    "an image of the wrong size": (
        "route",
        lambda f: cv2.imwrite(str(f / "image00002.png"), np.zeros((48, 100), np.uint8)),
        r"image00002\.png: image is 100x48 \(width x height\), expected 288x60",
    ),
    "an image linked from outside": (
        "route",
        lambda f: _link_out(f, "image00003.png"),
        ENTRIES + r":4: image00003\.png leads through a symbolic link to .*outside-image00003"
        r"\.png, outside the database folder",
    ),
    "a folder linked from outside": (
        "route",
        _link_folder_out,
        ENTRIES + r":4: sub/image00003\.png leads through a symbolic link to .*elsewhere/",
    ),
    "the entries linked from outside": (
        "route",
        lambda f: _link_out(f, "database_entries.csv"),
        ENTRIES + r": database_entries\.csv leads through a symbolic link to .*outside-database_",
    ),
    "the metadata linked from outside": (
        "grid",
        lambda f: _link_out(f, "database_metadata.yaml"),
        METADATA + r": database_metadata\.yaml leads through a symbolic link to .*outside-",
    ),
    "raw images without an unwrapper": (
        "route",
        lambda f: _edit(f, "database_metadata.yaml", "needsUnwrapping: 0", "needsUnwrapping: 1"),
        METADATA + r": raw images \(needsUnwrapping: 1\) of camera opengl, but no unwrapper .* "
        r"add images\.raw\.catadioptric .* to .*homebench\.yaml",
    ),
    "overrides of the other kind": (
        "route",
        lambda f: (f / "homebench.yaml").write_text(RAW_OVERRIDES),
        r"homebench\.yaml: images\.raw: .*database_metadata\.yaml says needsUnwrapping: 0: "
        r"describe the images as images\.unfolded",
    ),
    "a zero column off the image": (
        "route",
        lambda f: (f / "homebench.yaml").write_text(
            "images: {unfolded: {panorama: {elevation_top_deg: 30, elevation_bottom_deg: -30, "
            "zero_column: 300}}}\n"
        ),
        r"homebench\.yaml: images\.unfolded\.panorama: panorama\.zero_column 300 is not a column "
        r"of the 288-wide image",
    ),
    "an unknown override": (
        "route",
        lambda f: (f / "homebench.yaml").write_text("heading_deg: 90\n"),
        r"homebench\.yaml:1: unknown key 'heading_deg' \(did you mean 'headings'\?\)",
    ),
}


@pytest.mark.parametrize("case", list(BAD_INPUTS))
def test_bad_input_is_one_line_naming_the_file(
    case: str, sources: dict[str, Path], tmp_path: Path
) -> None:
    source, spoil, expected = BAD_INPUTS[case]
    folder = tmp_path / source
    shutil.copytree(sources[source], folder)
    spoil(folder)
    result = CliRunner().invoke(main, ["data", "verify", str(folder)])
    assert result.exit_code == 2, result.output
    errors = [line for line in result.stderr.splitlines() if "homebench: note:" not in line]
    assert len(errors) == 1 and errors[0].startswith("homebench: error: "), result.stderr
    assert re.search(expected, errors[0]), errors[0]


def test_links_inside_the_folder_are_followed(sources: dict[str, Path], tmp_path: Path) -> None:
    folder = tmp_path / "route"
    shutil.copytree(sources["route"], folder)
    (folder / "image00003.png").unlink()
    (folder / "image00003.png").symlink_to("image00002.png")
    (tmp_path / "linked").symlink_to(folder)
    result = CliRunner().invoke(main, ["data", "verify", str(tmp_path / "linked")])
    assert result.exit_code == 0 and "10 images OK" in result.stdout, result.output


def test_the_entries_file_is_bounded(
    sources: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = tmp_path / "route"
    shutil.copytree(sources["route"], folder)
    monkeypatch.setattr(entries, "MAX_ENTRIES", 9)
    with pytest.raises(DataError, match=r"database_entries\.csv: more than 9 images"):
        open_bob(folder)
    size = (folder / "database_entries.csv").stat().st_size
    monkeypatch.setattr(entries, "MAX_ENTRIES_BYTES", size - 1)
    with pytest.raises(DataError, match=r"database_entries\.csv: the entries file is larger"):
        open_bob(folder)


def test_nothing_in_the_metadata_is_executed(sources: dict[str, Path], tmp_path: Path) -> None:
    folder = tmp_path / "grid"
    shutil.copytree(sources["grid"], folder)
    marker = tmp_path / "executed"
    _metadata(folder, f'metadata: !!python/object/apply:os.system ["touch {marker}"]\n')
    with pytest.raises(ConfigError, match="could not determine a constructor"):
        open_bob(folder)
    assert not marker.exists()


def test_opencv_yaml_keeps_its_lines_and_reads_matrices_as_mappings() -> None:
    text = (
        "%YAML:1.0\n---\nm: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: d\n"
        "   data: [ 1., 2. ]\n"
    )
    converted = as_yaml(text)
    assert len(converted) == len(text) and converted.count("\n") == text.count("\n")
    assert "!!" not in converted and converted.splitlines()[2].rstrip() == "m:"
    matrix = {"rows": 1, "cols": 2, "dt": "d", "data": [1.0, 2.0]}
    assert yaml.safe_load(converted) == {"m": matrix}
    assert as_yaml("a: '!!opencv-matrix'\n") == "a: '!!opencv-matrix'\n"  # a string stays


def test_raw_images_are_unwrapped_where_bob_unwraps_them(tmp_path: Path) -> None:
    """Column j of BoB's unwrapped panorama samples ``centre + r (-sin t, cos t)``, t = 360 j /
    w + offset: homebench's model puts azimuth 2 pi j / w there, at the elevations assumed."""
    size = (160, 120)
    for flip in (False, True):
        unwrapper = Unwrapper(
            centre=(0.5, 0.45), inner=0.1, outer=0.45, offsetDegrees=30, flip=flip
        )
        model = from_unwrapper(unwrapper, size)
        assert model.centre == (80.0, 54.0) and model.radii == (12.0, 54.0)
        columns, width = np.arange(0, 360, 7), 360
        for radius in (12.0, 30.0, 54.0):
            t = np.radians(360.0 * columns / width + 30.0)
            bob_u, bob_v = 80.0 - radius * np.sin(t), 54.0 + radius * np.cos(t)
            u, v = model.bearing_to_pixel(
                2 * np.pi * columns / width, model.radius_to_elevation(radius)
            )
            assert np.allclose(u, bob_u) and np.allclose(v, bob_v)
        up_inside = model.radius_to_elevation(12.0) > model.radius_to_elevation(54.0)
        assert up_inside != flip  # BoB's top row samples the inner radius, flipped the outer
        assert model.horizon_radius == pytest.approx(33.0)
        assert math.degrees(max(model.elevations)) == pytest.approx(math.degrees(42 / 66))

    folder = tmp_path / "raw"
    folder.mkdir()
    rng = np.random.default_rng(3)
    lines = ["X [mm], Y [mm], Z [mm], Heading [degrees], Filename"]
    for k in range(3):
        cv2.imwrite(str(folder / f"image{k:05d}.jpg"), rng.integers(0, 255, (120, 160), np.uint8))
        lines.append(f"{k * 100}, 0, 0, 0, image{k:05d}.jpg")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (folder / "database_metadata.yaml").write_text(
        ROUTE_METADATA.replace("288, 60", "160, 120").replace(
            "needsUnwrapping: 0", "needsUnwrapping: 1"
        )
        + "   unwrapper:\n      centre: [ 0.5, 0.45 ]\n      inner: 0.1\n      outer: 0.45\n"
        "      offsetDegrees: 30\n      flip: 0\n"
    )
    db = open_bob(folder)
    bob = from_unwrapper(
        Unwrapper(centre=(0.5, 0.45), inner=0.1, outer=0.45, offsetDegrees=30), size
    )
    assert db.kind == "raw" and db.camera.centre == bob.centre and db.camera.radii == bob.radii
    assert db.camera.elevations == pytest.approx(bob.elevations, abs=1e-9)
    assert db.camera.zero_angle == pytest.approx(bob.zero_angle) and db.camera.direction == "cw"
    assert len(db.notes) == 2 and "the unwrapper gives no elevations" in db.notes[0]
    assert "compass bearings" in db.notes[1]  # and the headings, as BoB writes them
    result = CliRunner().invoke(main, ["data", "verify", str(folder)])
    assert result.exit_code == 0 and "3 images OK" in result.stdout, result.output


def test_grid_positions_rounded_to_millimetres_fit_their_grid() -> None:
    ij = np.array([(i, j) for i in range(4) for j in range(3)])
    noise = np.random.default_rng(1).uniform(-0.0005, 0.0005, ij.shape)
    grid = fit_grid(ij * 0.25 + (1.0, -2.0) + noise, ij, "entries", str)
    assert grid.shape == (4, 3)
    assert grid.spacing == pytest.approx(0.25, abs=3e-4)
    assert grid.origin == pytest.approx((1.0, -2.0), abs=1e-3)
    with pytest.raises(DataError, match=r"a grid of 1 recorded position\(s\) has no spacing"):
        fit_grid(np.zeros((1, 2)), np.zeros((1, 2), np.int64), "entries", str)
    with pytest.raises(DataError, match=r"a grid of 0 recorded position\(s\) has no spacing"):
        fit_grid(np.zeros((0, 2)), np.zeros((0, 2), np.int64), "entries", str)
