"""Brains on Board image databases: folders written by hand the way BoB's Ant World tools
write them (tests/bob_folders.py: compass headings, columns and rows by BoB's renderer's
formula) through every data command, as API objects, in a run, and generated worlds written in
the format and read back.

The grid's images are the analytic arena's, where warping homes exactly: with each image's own
heading the home directions of pairs whose images face different ways come out right, with one
heading for all 45 to 170 deg wrong.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from bob_folders import (
    GRID_SHAPE,
    HEADING_DEG,
    HEIGHT,
    ROUTE_POSES,
    TURNED_DEG,
    WIDTH,
    bob_bearings_deg,
    bob_elevations_deg,
    grid_heading_deg,
    grid_position_mm,
    route_poses,
    write_grid,
    write_route,
)
from click.testing import CliRunner, Result
from conftest import run_config
from test_database import make_user_database
from test_generate import FakeRenderer, small_spec

from homebench.cli import EXIT_CHECK, main
from homebench.data.bob import BobOverrides, open_bob, write_bob
from homebench.data.catalog import find_manifest, resolve
from homebench.data.database import GridDatabase
from homebench.data.generate import generate, manifest_for_spec
from homebench.data.manifest import Manifest, load_manifest
from homebench.errors import ConfigError
from homebench.fileio import read_grey
from homebench.geometry import angle_diff, angular_error, home_direction
from homebench.methods import registry


@pytest.fixture(scope="module")
def grid(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_grid(tmp_path_factory.mktemp("bob") / "arena-grid")


@pytest.fixture(scope="module")
def route(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_route(tmp_path_factory.mktemp("bob") / "arena-route")


def _data(*args: str) -> Result:
    return CliRunner().invoke(main, ["data", *args])


def _error_line(result: Result) -> str:
    """The one line of a data error (exit 2)."""
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    errors = [line for line in lines if not line.startswith("homebench: note:")]
    assert len(errors) == 1 and errors[0].startswith("homebench: error: "), result.stderr
    return errors[0]


def test_every_data_command_reads_a_grid_folder(grid: Path, tmp_path: Path) -> None:
    verified = _data("verify", str(grid))
    assert verified.exit_code == 0, verified.output
    assert f"arena-grid ({grid}): 25 images OK in {grid} (a 5 x 5 grid 0.3 m apart" in (
        verified.stdout
    )
    notes = [line for line in verified.stderr.splitlines() if "homebench: note:" in line]
    assert len(notes) == 3, verified.stderr
    assert "camera 'opengl': read as BoB's Ant World renders" in notes[0]
    assert (
        "elevation_top_deg 60, elevation_bottom_deg -15, direction cw, zero_column 143.5"
        in (notes[0])
    )
    assert "compass bearings, 0 along +y, growing clockwise" in notes[1]
    assert "grid.order: bob-recorder" in notes[2] and "homebench data check" in notes[2]

    shown = _data("show", str(grid), "--out", str(tmp_path), "--at", "1", "2")
    assert shown.exit_code == 0, shown.output
    assert (tmp_path / "arena-grid_contact_sheet.png").stat().st_size > 10_000

    checked = _data("check", str(grid))
    assert checked.exit_code == 0, checked.output
    assert "the manifest agrees with the images" in checked.stdout


def _homebench(*args: str) -> subprocess.CompletedProcess[str]:
    """``homebench ARGS`` in a process of its own, as a user types it."""
    return subprocess.run(
        [sys.executable, "-m", "homebench", *args],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip


@pytest.mark.slow  # CI time: docs/tutorials/own-bob.md runs verify, check and run in processes
def test_every_command_in_a_process_of_its_own(grid: Path, tmp_path: Path) -> None:
    """The hand-written folder through every data command and a run, each a real process."""
    verified = _homebench("data", "verify", str(grid))
    assert verified.returncode == 0, verified.stderr
    assert "25 images OK" in verified.stdout and "a 5 x 5 grid 0.3 m apart" in verified.stdout
    assert "read as BoB's Ant World renders" in verified.stderr

    shown = _homebench("data", "show", str(grid), "--out", str(tmp_path))
    assert shown.returncode == 0, shown.stderr
    assert (tmp_path / "arena-grid_contact_sheet.png").is_file()

    checked = _homebench("data", "check", str(grid))
    assert checked.returncode == 0, checked.stderr + checked.stdout
    assert "the manifest agrees with the images" in checked.stdout

    config = tmp_path / "run.yaml"
    config.write_text(yaml.safe_dump({
        "name": "bob-process", "output": str(tmp_path / "run"), "databases": {"arena": str(grid)},
        "conditions": ["arena-arena"], "goals": [[1, 2]], "methods": [{"method": "warping"}],
    }))  # fmt: skip
    ran = _homebench("run", str(config), "--no-progress", "--no-report")
    assert ran.returncode == 0, ran.stderr
    assert "warping" in ran.stdout
    assert "read as BoB's Ant World renders" in ran.stdout + ran.stderr
    pairs = (tmp_path / "run" / "tables" / "pairs.csv").read_text().splitlines()
    assert len(pairs) == 1 + 24


def _world_deg(compass_deg: float) -> float:
    """The ccw angle from +x (deg, in [0, 360)) of a compass bearing."""
    return (90.0 - compass_deg) % 360.0


def test_grid_positions_in_metres_and_each_image_its_heading(grid: Path) -> None:
    db = resolve(grid)
    assert isinstance(db, GridDatabase) and db.kinds == ("unfolded",)
    assert db.grid.shape == GRID_SHAPE and db.grid.spacing == 0.3
    assert db.grid.origin == (-0.6, -0.45)
    for i, j in db.grid.indices():
        pose = db.pose(i, j)
        x, y = grid_position_mm(i, j)
        assert (pose.x, pose.y) == pytest.approx((x / 1000, y / 1000), abs=1e-12)
        assert pose.heading == pytest.approx(math.radians(_world_deg(grid_heading_deg(i, j))))
    assert db.manifest.heading_deg == _world_deg(HEADING_DEG)
    assert db.manifest.headings_deg == {
        f"{i}_{j}": _world_deg(h) for (i, j), h in TURNED_DEG.items()
    }
    colour = read_grey(db.path(2, 2, "unfolded"))  # written in colour, read as grey
    assert colour.shape == (HEIGHT, WIDTH)


def test_every_pixel_looks_where_bobs_renderer_points_it(grid: Path) -> None:
    """homebench's reading of an Ant World image against BoB's formula (bob_folders.py): each
    column's world direction from the pose and camera model homebench reads, each row's
    elevation, for an image facing the shared heading and for one turned to 200 deg."""
    db = resolve(grid)
    geometry = db.geometry("unfolded")
    rows = geometry.row_to_elevation(np.arange(HEIGHT))
    assert np.degrees(rows) == pytest.approx(bob_elevations_deg(), abs=1e-9)
    for i, j in [(0, 0), (4, 0)]:
        world = db.heading(i, j) + geometry.column_to_azimuth(np.arange(WIDTH))
        bob_world = np.radians(90.0 - bob_bearings_deg(grid_heading_deg(i, j)))
        assert np.degrees(np.abs(angle_diff(world, bob_world))).max() < 1e-9


def test_a_per_image_heading_turns_the_true_home_direction(grid: Path) -> None:
    db, warping = resolve(grid), registry.create("warping")
    for current, goal in [((1, 2), (2, 2)), ((3, 3), (2, 3)), ((4, 0), (4, 1))]:
        estimate = warping.home(
            warping.describe(db.view(*current, "unfolded")),
            warping.describe(db.view(*goal, "unfolded")),
        ).angle
        c, g = db.pose(*current), db.pose(*goal)
        truth = home_direction(c.xy, g.xy, c.heading)  # within a step of warping's 5 deg grid
        assert math.degrees(angular_error(estimate, truth)) <= 5.0 + 1e-9
        shared = home_direction(c.xy, g.xy, math.radians(_world_deg(HEADING_DEG)))
        assert math.degrees(angular_error(estimate, shared)) > 40


def test_a_run_names_the_folder_as_its_database(grid: Path, tmp_path: Path) -> None:
    config = {
        "name": "bob-run",
        "output": str(tmp_path / "run"),
        "databases": {"arena": str(grid)},
        "conditions": ["arena-arena"],
        "goals": [[1, 2], [4, 0]],
        "methods": [{"method": "warping"}],
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    pairs = (tmp_path / "run" / "tables" / "pairs.csv").read_text().splitlines()
    assert len(pairs) == 1 + 2 * 24


def test_a_config_entry_states_the_camera(grid: Path, tmp_path: Path) -> None:
    """``images`` of a database entry replaces the assumed camera model (and its note); it is
    refused for a database that states its own."""
    panorama = {"elevation_top_deg": 60.0, "elevation_bottom_deg": -15.0, "direction": "cw",
                "zero_column": 143.5}  # fmt: skip
    config = {
        "name": "bob-images", "output": str(tmp_path / "run"),
        "databases": {"arena": {"name": str(grid), "images": {"unfolded": {"panorama": panorama}}}},
        "conditions": ["arena-arena"], "goals": [[4, 0]], "methods": [{"method": "warping"}],
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "read as BoB's Ant World renders" not in result.output + result.stderr

    config["databases"] = {"arena": {"name": "synth-original", "images": config["databases"][
        "arena"]["images"]}}  # fmt: skip
    refused = run_config(tmp_path, config)
    assert refused.exit_code == 2 and "are for Brains on Board database folders" in refused.stderr

    config["databases"] = {"arena": {"world": {}, "images": {}}}
    refused = run_config(tmp_path, config)
    assert refused.exit_code == 2 and "'images' is for Brains on Board folders" in refused.stderr


def test_a_route_folder_is_verified_shown_and_too_short_for_data_check(
    route: Path, tmp_path: Path
) -> None:
    verified = _data("verify", str(route))
    assert verified.exit_code == 0, verified.output
    assert f"{ROUTE_POSES} images OK" in verified.stdout
    assert "a route of 10 poses, 1.57 m long" in verified.stdout
    line = _error_line(_data("check", str(route)))
    assert str(route) in line and "needs 20 such pairs for a verdict" in line
    assert "a route of 10 poses, 1.57 m long gives 10" in line
    shown = _data("show", str(route), "--out", str(tmp_path))
    assert shown.exit_code == 0, shown.output
    assert "a route of 10 poses, 1.57 m long, not a grid" in shown.stdout
    assert (tmp_path / "arena-route_poses.png").is_file()
    outside = _error_line(_data("show", str(route), "--out", str(tmp_path), "--at", "3", "1"))
    assert "holds 10 posed images, not a grid: image k is place (k, 0), k in 0..9" in outside
    places = resolve(route)  # what a run reads: image k at (k, 0) of posed places
    assert places.grid.shape == (ROUTE_POSES, 1)
    x, y, _ = route_poses()[4]
    assert places.pose(4, 0).x == pytest.approx(x / 1000)
    assert places.pose(4, 0).y == pytest.approx(y / 1000)


def test_route_poses_keep_their_order_in_metres_and_radians(route: Path) -> None:
    db = open_bob(route)
    assert db.grid is None and len(db) == ROUTE_POSES and db.kinds == ("unfolded",)
    for k, (x, y, heading) in enumerate(route_poses()):
        pose = db.pose(k)
        assert (pose.x, pose.y) == pytest.approx((x / 1000, y / 1000), abs=1e-12)
        assert pose.heading == pytest.approx(math.radians(_world_deg(heading)))
        assert db.path(k).name == f"image{k + 1:05d}.png"
    assert db.view(3).image.shape == (HEIGHT, WIDTH)


def test_a_generated_world_round_trips_through_the_format(tmp_path: Path) -> None:
    manifest = tmp_path / "tiny.yaml"
    manifest.write_text(manifest_for_spec(small_spec(seed=11), "tiny-world").to_yaml())
    out = tmp_path / "tiny-bob"
    args = ["generate", str(manifest), "--format", "bob", "--out", str(out), "--jobs", "1"]
    result = _data(*args, "--no-progress")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("tiny-world: generated in ")
    assert result.stdout.strip().endswith(f" in {out}")  # the folder written, not the cache
    entries = (out / "database_entries.csv").read_text().splitlines()
    assert entries[0].startswith("X [mm], Y [mm], Z [mm], Heading [degrees], Filename, Grid X")
    assert (out / "database_metadata.yaml").read_text().startswith("%YAML:1.0\n")

    generated, written = resolve(manifest), resolve(out)
    assert written.name == "tiny-world" and written.grid == generated.grid
    assert written.geometry("unfolded") == generated.geometry("unfolded")
    for i, j in generated.grid.indices():
        assert written.pose(i, j) == generated.pose(i, j)
        assert written.path(i, j, "unfolded").read_bytes() == (
            generated.path(i, j, "unfolded").read_bytes()
        )
        assert np.array_equal(written.image(i, j, "unfolded"), generated.image(i, j, "unfolded"))
    verified = _data("verify", str(out))
    assert verified.exit_code == 0 and verified.stderr == "", verified.output
    assert _run_pairs(tmp_path / "gen", str(manifest)) == _run_pairs(tmp_path / "bob", str(out))

    assert "exists and is not empty" in _error_line(_data(*args))
    assert "--out" in _error_line(_data("generate", str(manifest), "--format", "bob"))


#: What a run finds for each pair, whatever the database is called.
RESULT_COLUMNS = (
    *("heading_rad", "goal_heading_rad", "estimate_rad", "truth_rad", "ae_rad"),
    *("rotation_estimate_rad", "distance_m", "n_landmarks", "score", "error"),
)


def _run_pairs(folder: Path, database: str) -> dict[tuple[str, ...], tuple[str, ...]]:
    """The results of a run of two methods over ``database``, by (method, goal, current)."""
    config = {
        "name": "round-trip", "output": str(folder / "run"), "databases": {"db": database},
        "conditions": ["db-db"], "goals": [[1, 2]],
        "methods": [{"method": "warping"}, {"method": "alv"}],
    }  # fmt: skip
    folder.mkdir()
    result = run_config(folder, config)
    assert result.exit_code == 0, result.output
    with (folder / "run" / "tables" / "pairs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    keys = ("method", "goal_i", "goal_j", "current_i", "current_j")
    pairs = {tuple(r[k] for k in keys): tuple(r[c] for c in RESULT_COLUMNS) for r in rows}
    assert len(pairs) == 2 * 11 and all(r["error"] == "" for r in rows)
    return pairs


@pytest.mark.parametrize("kind", ["unfolded", "raw"])
def test_a_manifest_database_round_trips_with_its_headings_and_camera(
    kind: str, tmp_path: Path
) -> None:
    """A user's database (per-position headings, clockwise panoramas with azimuth 0 at column
    5), and a raw-only one: written in the format, read back the same."""
    if kind == "unfolded":
        user = make_user_database(tmp_path / "user")
        source = GridDatabase(load_manifest(user / "manifest.yaml"), user)
    else:
        generated = resolve(generate(small_spec(seed=3), tmp_path / "gen", 1, "tiny",
                                     renderer=FakeRenderer()))  # fmt: skip
        data = generated.manifest.model_dump(by_alias=True, exclude={"generator", "ground_truth"})
        del data["images"]["unfolded"]
        source = GridDatabase(Manifest.model_validate(data), generated.root)
    written = open_bob(write_bob(source, tmp_path / "bob"))
    assert written.kind == kind and written.notes == () and written.name == source.name
    assert _same_model(written.camera, source.geometry(kind))
    back = written.grid_database()
    assert back.grid == source.grid
    headings = {k: h % 360.0 for k, h in source.manifest.headings_deg.items()}
    assert back.manifest.headings_deg == pytest.approx(headings)  # read back in [0, 360)
    for i, j in source.grid.indices():
        pose, expected = back.pose(i, j), source.pose(i, j)
        assert pose.xy == pytest.approx(expected.xy)
        assert angle_diff(pose.heading, expected.heading) == pytest.approx(0.0, abs=1e-12)
        assert back.path(i, j, kind).read_bytes() == source.path(i, j, kind).read_bytes()


def _same_model(a: object, b: object) -> bool:
    """Camera models equal up to the 1e-9 deg rounding of a manifest's degrees."""
    return all(
        x == y if isinstance(x, str) else np.allclose(x, y, atol=1e-9)
        for x, y in zip(dataclasses.astuple(a), dataclasses.astuple(b), strict=True)
    )


def test_homebench_yaml_states_the_camera_and_a_config_overrides_it(
    grid: Path, tmp_path: Path
) -> None:
    """A key of homebench.yaml replaces one default (the others kept, and named in the note);
    data check finds a wrong one; a config's section replaces the file's."""
    folder = tmp_path / "g"
    shutil.copytree(grid, folder)
    own = {"name": "our-arena", "grid": {"order": "as-written"},
           "headings": {"zero_deg": 90, "direction": "cw"},
           "images": {"unfolded": {"panorama": {"zero_column": 72.0}}}}  # fmt: skip
    (folder / "homebench.yaml").write_text(yaml.safe_dump(own))
    db = open_bob(folder)
    assert db.name == "our-arena" and db.camera.zero_column == 72.0
    assert db.camera.direction == "cw" and len(db.notes) == 1
    assert "elevation_top_deg 60, elevation_bottom_deg -15, direction cw;" in db.notes[0]

    checked = _data("check", str(folder))  # the heading lies at column 143.5, not 72 (89 deg)
    assert checked.exit_code == EXIT_CHECK, checked.output
    fix = re.search(
        r"set images\.unfolded\.panorama\.zero_column: ([0-9.]+) \(manifest: 72", checked.stdout
    )
    assert fix is not None and abs(float(fix[1]) - 143.5) < 1.5, checked.stdout
    assert "heading_deg" not in checked.stdout  # headings come from the CSV, not a manifest

    config = BobOverrides.model_validate({"images": {"unfolded": {"panorama": {
        "elevation_top_deg": 60, "elevation_bottom_deg": -15}}}})  # fmt: skip
    database = resolve(folder, overrides=config)
    assert database.name == "our-arena" and database.geometry("unfolded").zero_column == 143.5
    assert find_manifest(folder, overrides=config)[0].images.unfolded.panorama.zero_column == 143.5
    with pytest.raises(ConfigError, match="are for Brains on Board database folders"):
        resolve("synth-original", overrides=config)
    with pytest.raises(ConfigError, match="read from its own folder"):
        resolve(folder, tmp_path)
