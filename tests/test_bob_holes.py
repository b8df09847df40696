"""Real Brains on Board databases have holes (issue 37, item 3): folders written by hand the
way BoB writes them (tests/bob_folders.py), checked against where their images were rendered.

- A block of labels cut from a recorder grid reads as a grid starting at 0, its positions
  mapped through the whole grid's size (the metadata's) in BoB's recorder order: on a square
  grid a transposed block, on an oblong one a scattered one, with holes.
- A grid with a failed capture runs end to end over the positions present, RR as the README
  says; a row whose pose was lost is left out with a count, or placed by
  ``missing_poses: interpolate``: a route's between its neighbours, as navbench does, its
  heading along the direction of travel in the folder's heading convention.
- Metadata that disagrees with the entries is a warning.
"""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from bob_folders import (
    GRID_SHAPE,
    bend_points,
    grid_heading_deg,
    grid_name,
    grid_position_mm,
    recorder_images,
    route_poses,
    write_grid,
    write_recorder_grid,
    write_route,
)
from click.testing import CliRunner, Result
from conftest import run_config
from test_bob import _homebench, _world_deg

from homebench.cli import EXIT_CHECK, main
from homebench.data.bob import BobOverrides, open_bob
from homebench.data.catalog import resolve
from homebench.geometry import missing_positions

#: The grid position whose capture failed.
FAILED = (3, 2)
#: Route rows that lost values: the first (nothing before it to interpolate from), two in a
#: row on the straight stretch east, a heading on it, a Y on the stretch north, the last
#: one's heading.
LOST = {
    0: ("X", "Y"),
    4: ("X", "Y", "Heading"),
    5: ("X", "Y"),
    8: ("Heading",),
    27: ("Y",),
    33: ("Heading",),
}
POINTS = bend_points(100.0)  # 34 points: 12 east, 9 in the bend, 13 north


def _data(*args: str) -> Result:
    return CliRunner().invoke(main, ["data", *args])


def _lines(text: str, kind: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith(f"homebench: {kind}: ")]


@pytest.fixture(scope="module")
def failed_grid(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_grid(tmp_path_factory.mktemp("holes") / "failed", failed={FAILED})


@pytest.fixture(scope="module")
def lossy_route(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_route(tmp_path_factory.mktemp("holes") / "lossy", POINTS, lost=LOST)


# --------------------------------------------------------------------------- blocks


def _rendered_at(folder: Path, block: tuple[range, range], shape: tuple[int, int]) -> None:
    """Every image of the cut ``folder`` read where BoB's recorder rendered it."""
    posed = open_bob(folder)
    taken = {grid_name(*grid_position_mm(*label)): xy for label, xy in
             recorder_images(shape, block).items()}  # fmt: skip
    assert sorted(posed.files) == sorted(taken)
    for k, name in enumerate(posed.files):
        assert posed.xy[k] == pytest.approx(np.array(taken[name]) / 1000.0, abs=1e-9), name
    db = posed.grid_database()
    for (i, j), name in db.files.items():  # the grid index of an image is where it was taken
        assert db.grid.position(i, j) == pytest.approx(np.array(taken[name]) / 1000.0, abs=1e-9)


def test_a_block_cut_from_a_square_recorder_grid_reads_where_its_images_were_rendered(
    tmp_path: Path,
) -> None:
    """Grid X 4..8, Grid Y 5..8 of a 12 x 12 recorder grid (BoB's Ant World grid is 101 x
    101): read in BoB's recorder order, the block's positions are transposed, (5..8, 4..8),
    and start at 0; the note says goal [0, 0] is the image labelled (4, 5)."""
    block, shape = (range(4, 9), range(5, 9)), (12, 12)
    folder = write_recorder_grid(tmp_path / "block", shape, block)
    (folder / "homebench.yaml").write_text("grid: {order: bob-recorder}\n")
    _rendered_at(folder, block, shape)
    posed = open_bob(folder)
    assert posed.grid is not None and posed.grid.shape == (4, 5)
    assert missing_positions(posed.grid) == () and posed.warnings == ()
    (shift,) = [note for note in posed.notes if "not (0, 0)" in note]
    assert "the 12 x 12 grid they were recorded on start at (5, 4), not (0, 0)" in shift
    assert "goal [0, 0] is the image labelled (4, 5)" in shift
    assert posed.grid_database().files[(0, 0)] == grid_name(*grid_position_mm(4, 5))


@pytest.fixture(scope="module")
def oblong_block(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Grid X 1..7, Grid Y 1..5 of a 9 x 7 recorder grid, as written (no grid.order)."""
    folder = tmp_path_factory.mktemp("holes") / "oblong-block"
    return write_recorder_grid(folder, (9, 7), (range(1, 8), range(1, 6)))


def test_a_block_cut_from_an_oblong_recorder_grid_lands_where_bob_rendered_it(
    oblong_block: Path, tmp_path: Path
) -> None:
    """On an oblong grid BoB's recorder order scatters a block of labels: mapped through the
    metadata's 9 x 7 (not the block's span), its 35 images land where they were rendered,
    among holes; ``data check`` finds the order from the images, on the whole grid's size."""
    folder = tmp_path / "ordered"
    shutil.copytree(oblong_block, folder)
    (folder / "homebench.yaml").write_text("grid: {order: bob-recorder}\n")
    _rendered_at(folder, (range(1, 8), range(1, 6)), (9, 7))
    posed = open_bob(folder)
    assert posed.grid is not None
    nx, ny = posed.grid.shape
    assert len(missing_positions(posed.grid)) == nx * ny - 35 > 0
    assert any(f"of the {nx} x {ny} grid have no image" in note for note in posed.notes)

    checked = _data("check", str(oblong_block))  # as written: the labels are no positions
    assert checked.exit_code == EXIT_CHECK, checked.output
    fixes = checked.stdout.split("correct it:")[1].strip().splitlines()
    assert fixes == ["set grid.order: bob-recorder (manifest: as-written)"], checked.stdout
    agreed = _data("check", str(folder))
    assert agreed.exit_code == 0, agreed.output


# --------------------------------------------------------------------------- a failed capture


def test_a_grid_with_a_failed_capture_runs_end_to_end(failed_grid: Path, tmp_path: Path) -> None:
    """One capture of the 5 x 5 grid failed (no row, no image): every command reads the 24
    positions present, with one note; a run in a process of its own homes them and gives RR
    and catchment over them (README: RR starts at the positions present)."""
    hole = "1 of the 25 positions of the 5 x 5 grid has no image (grid index [3, 2])"
    verified = _homebench("data", "verify", str(failed_grid))
    assert verified.returncode == 0, verified.stderr
    assert "24 images OK" in verified.stdout and "1 of its positions without an image" in (
        verified.stdout
    )
    assert sum(hole in line for line in _lines(verified.stderr, "note")) == 1, verified.stderr
    assert not _lines(verified.stderr, "warning"), verified.stderr

    shown = _data("show", str(failed_grid), "--out", str(tmp_path))
    assert shown.exit_code == 0, shown.output
    assert (tmp_path / "failed_contact_sheet.png").is_file()
    at_hole = _data("show", str(failed_grid), "--out", str(tmp_path), "--at", "3", "2")
    assert at_hole.exit_code == 2, at_hole.output
    assert "grid position (3,2) of database 'failed' has no image" in at_hole.stderr
    checked = _data("check", str(failed_grid))
    assert checked.exit_code == 0 and "the manifest agrees with the images" in checked.stdout

    config = tmp_path / "run.yaml"
    config.write_text(yaml.safe_dump({
        "name": "holes", "output": str(tmp_path / "run"), "conditions": ["arena-arena"],
        "databases": {"arena": str(failed_grid)}, "goals": [[1, 2], [4, 4]],
        "methods": [{"method": "warping"}],
    }))  # fmt: skip
    ran = _homebench("run", str(config), "--no-progress", "--no-report")
    assert ran.returncode == 0, ran.stderr
    assert sum(hole in line for line in _lines(ran.stderr, "note")) == 1, ran.stderr
    tables = tmp_path / "run" / "tables"
    pairs = pd.read_csv(tables / "pairs.csv")
    assert len(pairs) == 2 * 23
    currents = set(zip(pairs["current_i"], pairs["current_j"], strict=True))
    assert FAILED not in currents and len(currents) == 24
    goals = pd.read_csv(tables / "goals.csv")
    assert goals["rr"].notna().all() and goals["catchment"].notna().all(), goals
    starts = pd.read_csv(tables / "rr_starts.csv")
    assert len(starts) == 2 * 24
    assert FAILED not in set(zip(starts["start_i"], starts["start_j"], strict=True))


def test_a_goal_on_the_hole_is_one_line_and_leaves_what_any_goal_outside_leaves(
    failed_grid: Path, tmp_path: Path
) -> None:
    left = {}
    for name, goal in (("hole", list(FAILED)), ("outside", [7, 7])):
        config = {
            "name": "refused", "output": str(tmp_path / name / "run"),
            "databases": {"arena": str(failed_grid)}, "conditions": ["arena-arena"],
            "goals": [goal], "methods": [{"method": "warping"}],
        }  # fmt: skip
        (tmp_path / name).mkdir()
        result = run_config(tmp_path / name, config)
        assert result.exit_code == 2, result.output
        (error,) = _lines(result.stderr, "error")
        run = tmp_path / name / "run"
        left[name] = {str(p.relative_to(run)) for p in run.rglob("*")} if run.exists() else set()
        if name == "hole":
            assert "goals.0: (3, 2) is outside the 5 x 5 grid, 1 of whose positions have no " in (
                error
            )
    assert left["hole"] == left["outside"]


def test_a_grid_row_that_lost_its_pose_is_a_hole_or_is_placed_at_its_grid_point(
    tmp_path: Path,
) -> None:
    lost = {(2, 3): ("X", "Y"), (0, 1): ("Heading",)}
    folder = write_grid(tmp_path / "lost", lost=lost)
    skipped = open_bob(folder)
    assert skipped.grid is not None
    assert missing_positions(skipped.grid) == ((0, 1), (2, 3)) and len(skipped) == 23
    (note,) = [note for note in skipped.notes if "rows have no" in note]
    assert "2 of the 25 rows have no X [mm], Y [mm] or Heading [degrees]" in note
    assert "left out, their images unread (missing_poses: skip" in note
    verified = _data("verify", str(folder))  # their images are listed, not stray files
    assert verified.exit_code == 0 and not _lines(verified.stderr, "warning"), verified.output

    (folder / "homebench.yaml").write_text("missing_poses: interpolate\n")
    placed = open_bob(folder)
    assert placed.grid is not None and missing_positions(placed.grid) == ((0, 1),)
    db = placed.grid_database()
    pose = db.pose(2, 3)  # at its grid point, with its own heading
    assert (pose.x, pose.y) == pytest.approx(np.array(grid_position_mm(2, 3)) / 1000, abs=1e-9)
    assert pose.heading == pytest.approx(math.radians(_world_deg(grid_heading_deg(2, 3))))
    (note,) = [note for note in placed.notes if "rows have no" in note]
    assert "1 placed at their Grid X, Grid Y, 1 left out (no heading" in note


# --------------------------------------------------------------------------- routes


def _truth(k: int) -> tuple[float, float, float]:
    """Row k's pose as rendered: x, y (m), heading (radians, ccw from +x)."""
    x, y, compass = route_poses(POINTS)[k]
    return x / 1000.0, y / 1000.0, math.radians(_world_deg(compass))


def _poses_match(folder: Path, rows: list[int]) -> None:
    """The images of ``folder`` are route rows ``rows``, each at its rendered pose."""
    posed = open_bob(folder)
    assert posed.files == tuple(f"image{k + 1:05d}.png" for k in rows)
    for n, k in enumerate(rows):
        pose, (x, y, heading) = posed.pose(n), _truth(k)
        assert (pose.x, pose.y) == pytest.approx((x, y), abs=1e-9), k
        assert abs(math.remainder(pose.heading - heading, math.tau)) < 1e-6, k


def test_route_rows_without_a_pose_are_left_out_with_a_count_and_the_route_runs(
    lossy_route: Path, tmp_path: Path
) -> None:
    kept = [k for k in range(len(POINTS)) if k not in LOST]
    _poses_match(lossy_route, kept)
    verified = _data("verify", str(lossy_route))
    assert verified.exit_code == 0, verified.output
    assert f"{len(kept)} images OK" in verified.stdout and not _lines(verified.stderr, "warning")
    (note,) = [line for line in _lines(verified.stderr, "note") if "rows have no" in line]
    assert re.search(
        r"database_entries\.csv: 6 of the 34 rows have no X \[mm\], Y \[mm\] or Heading "
        r"\[degrees\] \(empty or nan; line\(s\) 2, 6, 7 and 3 more\): left out, their images "
        r"unread \(missing_poses: skip; missing_poses: interpolate in .*homebench\.yaml places",
        note,
    ), note
    config = {
        "name": "lossy", "output": str(tmp_path / "run"), "databases": {"r": str(lossy_route)},
        "conditions": ["r-r"], "goals": [[0, 0]], "methods": [{"method": "warping"}],
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "6 of the 34 rows have no" in result.stderr
    assert len(pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")) == len(kept) - 1


def test_interpolate_places_route_rows_between_their_neighbours(
    lossy_route: Path, tmp_path: Path
) -> None:
    """Positions linearly between the rows around them, a lost heading along the direction
    of travel (into the row; out of it for none): on straight stretches exactly where the
    images were rendered. The first row has nothing before it and is left out."""
    folder = tmp_path / "interpolated"
    shutil.copytree(lossy_route, folder)
    (folder / "homebench.yaml").write_text("missing_poses: interpolate\n")
    _poses_match(folder, list(range(1, len(POINTS))))
    (note,) = [note for note in open_bob(folder).notes if "rows have no" in note]
    assert "5 placed between their neighbours (positions linearly by row, headings along" in note
    assert "1 left out (before the first position" in note

    overrides = BobOverrides(missing_poses="interpolate")  # a run config's database entry
    assert resolve(lossy_route, overrides=overrides).grid.shape == (len(POINTS) - 1, 1)
    config = {
        "name": "filled", "output": str(tmp_path / "run"), "conditions": ["r-r"],
        "databases": {"r": {"name": str(lossy_route), "missing_poses": "interpolate"}},
        "goals": [[0, 0]], "methods": [{"method": "warping"}],
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert len(pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")) == len(POINTS) - 2


def test_interpolated_headings_are_written_in_the_folders_heading_convention(
    lossy_route: Path, tmp_path: Path
) -> None:
    """A folder whose headings are ccw from +x (``headings: {zero_deg: 0, direction: ccw}``):
    the headings it lost are filled in that convention, so they read as the direction of
    travel as the others do, not as its mirror."""
    folder = tmp_path / "ccw"
    shutil.copytree(lossy_route, folder)
    entries = folder / "database_entries.csv"
    header, *rows = entries.read_text().splitlines()
    lines = [header]
    for row in rows:
        cells = row.split(", ")
        cells[3] = f"{(90.0 - float(cells[3])) % 360.0:g}" if cells[3] else ""
        lines.append(", ".join(cells))
    entries.write_text("\n".join(lines) + "\n")
    (folder / "homebench.yaml").write_text(
        "headings: {zero_deg: 0, direction: ccw}\nmissing_poses: interpolate\n"
    )
    _poses_match(folder, list(range(1, len(POINTS))))


def test_interpolation_goes_by_the_timestamps_where_every_row_has_one(tmp_path: Path) -> None:
    """navbench interpolates by Timestamp [ms]: a row recorded a third of the way in time
    between its neighbours lies a third of the way between them, not half."""
    points = [(-1200.0 + d, -900.0) for d in (0.0, 50.0, 100.0, 150.0, 300.0, 350.0)]
    folder = write_route(tmp_path / "timed", points, lost={3: ("X", "Y")},
                         timestamps_ms=[0.0, 50.0, 100.0, 150.0, 300.0, 350.0])  # fmt: skip
    (folder / "homebench.yaml").write_text("missing_poses: interpolate\n")
    posed = open_bob(folder)
    assert posed.xy[3] == pytest.approx([-1.05, -0.9], abs=1e-9)
    assert any("positions linearly by Timestamp [ms]" in note for note in posed.notes)


# --------------------------------------------------------------------------- metadata


def test_metadata_that_disagrees_with_the_entries_is_a_warning(tmp_path: Path) -> None:
    """A grid.size that does not hold the labels, a separationMM and a beginAtMM the
    positions do not fit: one warning each, the entries read; the data commands and a run
    print them."""
    folder = write_grid(tmp_path / "disagrees")
    metadata = folder / "database_metadata.yaml"
    text = metadata.read_text()
    edits = {
        "size: [ 5, 5, 1 ]": "size: [ 4, 5, 1 ]",
        "separationMM: [ 300., 300., 0. ]": "separationMM: [ 250., 250., 0. ]",
        "beginAtMM: [ -600., -450., 10. ]": "beginAtMM: [ 0., 0., 10. ]",
    }
    for old, new in edits.items():
        assert old in text
        text = text.replace(old, new)
    metadata.write_text(text)
    verified = _data("verify", str(folder))
    assert verified.exit_code == 0, verified.output
    assert "25 images OK" in verified.stdout and "a 5 x 5 grid 0.3 m apart" in verified.stdout
    warnings = _lines(verified.stderr, "warning")
    assert len(warnings) == 3, verified.stderr
    assert "grid.size [4, 5, 1] holds labels up to (3, 4), but Grid X, Grid Y in " in warnings[0]
    assert "run up to (4, 4): the grid they span from 0, 5 x 5, is read" in warnings[0]
    assert "grid.separationMM [250.0, 250.0, 0.0], but the positions in " in warnings[1]
    assert "are 300 mm apart: the positions are read" in warnings[1]
    assert "grid.beginAtMM [0.0, 0.0, 10.0], but the positions in" in warnings[2]
    assert "put Grid X, Grid Y (0, 0) at (-600, -450) mm" in warnings[2]
    assert open_bob(folder).grid_database().grid.shape == GRID_SHAPE

    config = {
        "name": "warned", "output": str(tmp_path / "run"), "databases": {"g": str(folder)},
        "conditions": ["g-g"], "goals": [[1, 2]], "methods": [{"method": "warping"}],
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    ran = _lines(result.stderr, "warning")
    assert len(ran) == 3 and "database 'g', disagrees" in ran[0], result.stderr
