"""Posed (non-grid) Brains on Board databases in runs: image k is the place (k, 0).

A tiny generated world is written as a BoB grid folder; the same folder without its Grid X,
Grid Y, Grid Z columns is posed places, whose pairs are the same images at the same poses: a
run over it must give the grid run's AE and AHC, and no RR. A route folder written by hand
(images copied from that world, some turned by whole columns with their headings turned alike;
the CSV and metadata typed as BoB's recorders leave them) goes through `homebench run` and
`homebench report` in processes of their own.
"""

from __future__ import annotations

import csv
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from conftest import run_config
from test_generate import small_spec

from homebench.cli import main
from homebench.data.generate import manifest_for_spec
from homebench.fileio import read_grey, write_png

#: Grid goals of the round trip (the tiny world is a 3 x 4 grid).
GRID_GOALS = [(1, 2), (2, 0)]
#: The hand-written route: grid positions of the world copied, and the turn (deg, ccw) of
#: each image (its compass heading turned alike, i.e. by -turn; the world's panoramas are 36
#: columns, 10 deg each).
ROUTE = [(0, 0), (1, 1), (2, 2), (2, 3), (1, 3)]
TURNS_DEG = [0, 30, -60, 90, 0]
METHODS = [{"method": "warping"}, {"method": "alv"}]


@pytest.fixture(scope="module")
def grid_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny world as a BoB grid folder (`homebench data generate --format bob`)."""
    folder = tmp_path_factory.mktemp("posed")
    manifest = folder / "tiny.yaml"
    manifest.write_text(manifest_for_spec(small_spec(seed=11), "tiny-world").to_yaml())
    out = folder / "tiny-bob"
    args = ["data", "generate", str(manifest), "--format", "bob", "--out", str(out)]
    result = CliRunner().invoke(main, [*args, "--jobs", "1", "--no-progress"])
    assert result.exit_code == 0, result.output
    return out


def _entries(folder: Path) -> list[dict[str, str]]:
    """The rows of a BoB entries file, cells stripped."""
    with (folder / "database_entries.csv").open(newline="") as f:
        return [{k.strip(): v.strip() for k, v in row.items()} for row in csv.DictReader(f)]


def _grid_index(grid_folder: Path) -> dict[tuple[int, int], int]:
    """The entries row (image k) of each grid position."""
    rows = _entries(grid_folder)
    return {(int(r["Grid X"]), int(r["Grid Y"])): k for k, r in enumerate(rows)}


@pytest.fixture(scope="module")
def posed_folder(grid_folder: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The grid folder without its Grid X, Grid Y, Grid Z columns: a route's metadata."""
    out = tmp_path_factory.mktemp("posed") / "tiny-posed"
    shutil.copytree(grid_folder, out)
    lines = (out / "database_entries.csv").read_text().splitlines()
    kept = [", ".join(line.split(", ")[:5]) for line in lines]
    assert kept[0] == "X [mm], Y [mm], Z [mm], Heading [degrees], Filename"
    (out / "database_entries.csv").write_text("\n".join(kept) + "\n")
    metadata = (out / "database_metadata.yaml").read_text().splitlines()
    grid_lines = {"   grid:", "      beginAtMM", "      separationMM", "      size"}
    metadata = [
        line.replace("type: grid", "type: route")
        for line in metadata
        if not any(line.startswith(start) for start in grid_lines)
    ]
    (out / "database_metadata.yaml").write_text("\n".join(metadata) + "\n")
    return out


def _run(folder: Path, database: Path, goals: list, **changes: object) -> Path:
    """A run of warping and alv over ``database`` towards ``goals``; its tables folder."""
    folder.mkdir()
    config = {
        "name": "posed", "output": str(folder / "run"), "databases": {"db": str(database)},
        "conditions": ["db-db"], "goals": goals, "methods": METHODS, **changes,
    }  # fmt: skip
    result = run_config(folder, config)
    assert result.exit_code == 0, result.output
    return folder / "run" / "tables"


def test_posed_places_give_the_grid_runs_ae_and_ahc_and_no_rr(
    grid_folder: Path, posed_folder: Path, tmp_path: Path
) -> None:
    index = _grid_index(grid_folder)
    grid = _run(tmp_path / "grid", grid_folder, [list(g) for g in GRID_GOALS])
    posed = _run(tmp_path / "posed", posed_folder, [[index[g], 0] for g in GRID_GOALS])

    grid_pairs, posed_pairs = pd.read_csv(grid / "pairs.csv"), pd.read_csv(posed / "pairs.csv")
    assert len(grid_pairs) == len(posed_pairs) == 2 * 2 * 11
    assert (posed_pairs["current_j"] == 0).all() and (posed_pairs["goal_j"] == 0).all()
    keys = ["method", "goal", "current"]
    grid_pairs["goal"] = [index[(i, j)] for i, j in grid_pairs[["goal_i", "goal_j"]].values]
    grid_pairs["current"] = [
        index[(i, j)] for i, j in grid_pairs[["current_i", "current_j"]].values
    ]
    posed_pairs = posed_pairs.assign(goal=posed_pairs.goal_i, current=posed_pairs.current_i)
    merged = grid_pairs.merge(posed_pairs, on=keys, suffixes=("_grid", "_posed"))
    assert len(merged) == len(grid_pairs)
    for column in ("ae_rad", "truth_rad", "estimate_rad", "heading_rad", "distance_m"):
        np.testing.assert_allclose(merged[f"{column}_posed"], merged[f"{column}_grid"], atol=1e-9)
    assert merged["ae_rad_posed"].notna().all()

    grid_summary, posed_summary = (
        pd.read_csv(t / "summary.csv").sort_values("method", ignore_index=True)
        for t in (grid, posed)
    )
    for column in ("ahc", "ahc_missing90", "mean_ae_deg", "pairs"):
        np.testing.assert_allclose(posed_summary[column], grid_summary[column], atol=1e-9)
    assert grid_summary["rr"].notna().all() and posed_summary["rr"].isna().all()
    assert pd.read_csv(posed / "goals.csv")["rr"].isna().all()
    assert len(pd.read_csv(posed / "rr_starts.csv")) == 0

    grid_ahc, posed_ahc = (pd.read_csv(t / "ahc.csv") for t in (grid, posed))
    np.testing.assert_allclose(posed_ahc["ahc"], grid_ahc["ahc"], atol=1e-9)
    grid_bands, posed_bands = (pd.read_csv(t / "bands.csv") for t in (grid, posed))
    np.testing.assert_allclose(posed_bands["pairs"], grid_bands["pairs"])
    np.testing.assert_allclose(posed_bands["ahc"], grid_bands["ahc"], atol=1e-9)

    runs = [str(tmp_path / name / "run") for name in ("grid", "posed")]
    for command in (["leaderboard", "--metric", "rr"], ["compare"]):
        read = CliRunner().invoke(main, [*command, *runs, "--label", "grid", "--label", "posed"])
        assert read.exit_code == 0, read.output
    board = CliRunner().invoke(main, ["leaderboard", *runs, "--label", "grid", "--label", "posed"])
    # the two are other databases (the images' positions are in their keys): a column each
    assert board.exit_code == 0, board.output
    assert board.stdout.count("db-db @ tiny-world-") == 2


def test_random_goals_and_a_distance_range_on_posed_places(
    posed_folder: Path, tmp_path: Path
) -> None:
    tables = _run(
        tmp_path / "range",
        posed_folder,
        {"random": 3, "seed": 5},
        currents={"min_distance": 0.35, "max_distance": 0.7},
        methods=[{"method": "alv"}],
    )
    pairs = pd.read_csv(tables / "pairs.csv")
    assert pairs[["goal_i", "goal_j"]].drop_duplicates().shape[0] == 3
    assert pairs["distance_m"].between(0.35 - 1e-9, 0.7 + 1e-9).all()
    xy = np.array([[float(r["X [mm]"]), float(r["Y [mm]"])] for r in _entries(posed_folder)])
    for (goal, k), group in pairs.groupby(["goal_i", "current_i"]):
        assert group["distance_m"].iloc[0] == pytest.approx(np.hypot(*(xy[goal] - xy[k])) / 1e3)
    within = np.hypot(*(xy[:, None] - xy[None]).T) / 1e3  # (n, n) metres
    expected = sum(
        int(((within[g] >= 0.35 - 1e-9) & (within[g] <= 0.7 + 1e-9)).sum())
        for g in pairs["goal_i"].unique()
    )
    assert len(pairs) == expected


ROUTE_METADATA = """\
%YAML:1.0
---
metadata:
   time: "2026-11-28 04:00:00"
   type: route
   camera:
      name: homebench
      resolution: [ {width}, {height} ]
      isPanoramic: 0
   needsUnwrapping: 0
"""


def _write_route(grid_folder: Path, out: Path) -> list[tuple[float, float, float]]:
    """A hand-written BoB route in ``out`` of the images of :data:`ROUTE` of the world, turned
    by :data:`TURNS_DEG` (rolled by whole columns: azimuth grows with the column, so turning
    ccw by d moves the scene d / 10 columns left, and lowers the compass heading BoB records by
    d); its poses (x mm, y mm, compass heading deg)."""
    out.mkdir()
    rows = {(int(r["Grid X"]), int(r["Grid Y"])): r for r in _entries(grid_folder)}
    lines, poses = ["X [mm], Y [mm], Z [mm], Heading [degrees], Filename"], []
    for k, (position, turn) in enumerate(zip(ROUTE, TURNS_DEG, strict=True)):
        row = rows[position]
        image = read_grey(grid_folder / row["Filename"])
        width = image.shape[1]
        name = f"image{k + 1:05d}.png"
        write_png(out / name, np.roll(image, -round(turn * width / 360), axis=1))
        x, y, heading = float(row["X [mm]"]), float(row["Y [mm]"]), float(row["Heading [degrees]"])
        poses.append((x, y, heading - turn))
        lines.append(f"{x:g}, {y:g}, {row['Z [mm]']}, {heading - turn:g}, {name}")
    (out / "database_entries.csv").write_text("\n".join(lines) + "\n")
    height, width = image.shape
    metadata = ROUTE_METADATA.replace("{width}", str(width)).replace("{height}", str(height))
    (out / "database_metadata.yaml").write_text(metadata)
    camera = yaml.safe_load((grid_folder / "homebench.yaml").read_text())
    camera.update(name="hand-route", description="five images of the tiny world, turned")
    (out / "homebench.yaml").write_text(yaml.safe_dump(camera, sort_keys=False))
    return poses


def _homebench(*args: str) -> subprocess.CompletedProcess[str]:
    """``homebench ARGS`` in a process of its own, as a user types it."""
    command = [sys.executable, "-m", "homebench", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)


@pytest.mark.slow  # CI time: docs/tutorials/own-bob.md checks and runs a BoB route in processes
def test_a_hand_written_route_runs_and_reports_in_processes(
    grid_folder: Path, tmp_path: Path
) -> None:
    poses = _write_route(grid_folder, tmp_path / "route")
    assert len({heading for _, _, heading in poses}) > 1
    goals = [[1, 0], [3, 0]]
    config = {
        "name": "route", "output": str(tmp_path / "run"),
        "databases": {"r": str(tmp_path / "route")}, "conditions": ["r-r"], "goals": goals,
        "methods": METHODS,
    }  # fmt: skip
    path = tmp_path / "route.yaml"
    path.write_text(yaml.safe_dump(config))
    ran = _homebench("run", str(path), "--no-progress", "--no-report", "--jobs", "1")
    assert ran.returncode == 0, ran.stderr
    reported = _homebench("report", str(tmp_path / "run"))
    assert reported.returncode == 0, reported.stderr
    assert (tmp_path / "run" / "report" / "report.pdf").is_file()
    figures = {p.stem for p in (tmp_path / "run" / "report" / "figures").glob("*.png")}
    assert not any("_fields_" in f or "_ae_" in f for f in figures), figures  # no grid maps

    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    expected = {(m["method"], g, k) for m in METHODS for g, _ in goals for k in range(5) if k != g}
    assert set(zip(pairs.method, pairs.goal_i, pairs.current_i, strict=True)) == expected
    assert len(pairs) == len(expected) and np.isfinite(pairs["ae_rad"]).all()
    for row in pairs.itertuples():  # the true home direction, in the current image's frame
        (x, y, compass), (gx, gy, _) = poses[row.current_i], poses[row.goal_i]
        heading = 90.0 - compass  # ccw from +x
        truth = math.atan2(gy - y, gx - x) - math.radians(heading)
        assert math.cos(row.truth_rad - truth) == pytest.approx(1.0, abs=1e-9)
        assert row.heading_deg == pytest.approx(heading % 360.0)
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv")
    assert summary["ahc"].notna().all() and summary["rr"].isna().all()
    assert (pd.read_csv(tmp_path / "run" / "tables" / "bands.csv")["pairs"].sum()) == len(pairs)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"methods": [{"method": "did"}]},
            "methods: 'did' (did) reads the grid neighbours of each current view, but database "
            "'db' holds posed images, not a grid",
        ),
        (
            {"methods": [{"method": "klt-sector"}]},
            "'klt-sector' (klt-sector) reads views along grid routes",
        ),
        ({"goals": [[2, 1]]}, "goals.0: (2, 1) is outside the 12 posed images (not a grid"),
        ({"goals": [[12, 0]]}, "a goal [k, 0] names image k, k = 0..11"),
    ],
)
def test_a_config_error_on_posed_places_exits_2_and_leaves_what_a_grid_run_leaves(
    grid_folder: Path, posed_folder: Path, tmp_path: Path, change: dict, message: str
) -> None:
    posed_line, posed_left = _refused(tmp_path / "posed", posed_folder, change)
    assert message in posed_line, posed_line
    _, grid_left = _refused(tmp_path / "grid", grid_folder, {"goals": [[7, 7]]})
    assert posed_left == grid_left  # a grid run's config error leaves the same


def _refused(folder: Path, database: Path, change: dict) -> tuple[str, set[str]]:
    """The one error line of a refused run over ``database`` (goal [3, 0], warping and alv,
    then ``change``) and the files it left in its run folder."""
    folder.mkdir()
    config = {
        "name": "refused", "output": str(folder / "run"), "databases": {"db": str(database)},
        "conditions": ["db-db"], "goals": [[3, 0]], "methods": METHODS, **change,
    }  # fmt: skip
    result = run_config(folder, config)
    assert result.exit_code == 2, result.output
    errors = [line for line in result.stderr.splitlines() if line.startswith("homebench: error")]
    assert len(errors) == 1, result.stderr
    run = folder / "run"
    return errors[0], {str(p.relative_to(run)) for p in run.rglob("*")} if run.exists() else set()


@pytest.mark.parametrize("other", ["grid", "route"])
def test_a_condition_pairs_posed_places_only_with_the_same_places(
    grid_folder: Path, posed_folder: Path, tmp_path: Path, other: str
) -> None:
    if other == "grid":
        database = grid_folder
    else:
        database = tmp_path / "route"
        _write_route(grid_folder, database)
    config = {
        "name": "mixed", "output": str(tmp_path / "run"),
        "databases": {"a": str(posed_folder), "b": str(database)},
        "conditions": ["a-b"], "goals": [[1, 0]], "methods": [{"method": "alv"}],
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 2, result.output
    assert "conditions: 'a-b' pairs databases with different places" in result.stderr
    assert not (tmp_path / "run" / "tables").exists()


def test_a_corrected_pose_recomputes_the_jobs_that_read_it(
    posed_folder: Path, tmp_path: Path
) -> None:
    """The images' contents are in every key; a posed database's poses are in its listing, so
    its jobs' keys hold them too: a resumed run does not reuse a result of the old pose."""
    folder = tmp_path / "edited"
    shutil.copytree(posed_folder, folder)
    config = {
        "name": "resume", "output": str(tmp_path / "run"), "databases": {"db": str(folder)},
        "conditions": ["db-db"], "goals": [[1, 0]], "methods": [{"method": "alv"}],
    }  # fmt: skip
    outputs = []
    for edit in (False, False, True):
        if edit:  # image 3's compass heading 90 deg more in the listing (ccw: 90 less)
            lines = (folder / "database_entries.csv").read_text().splitlines()
            cells = lines[4].split(", ")
            cells[3] = f"{float(cells[3]) + 90:g}"
            lines[4] = ", ".join(cells)
            (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
        result = run_config(tmp_path, config)
        assert result.exit_code == 0, result.output
        outputs.append(pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv"))
        computed = "1 job(s) computed, 0 reused" if edit or len(outputs) == 1 else "0 job(s) "
        assert computed in result.stdout, result.stdout
    before, after = (frame.set_index("current_i") for frame in outputs[1:])
    assert after.loc[3, "heading_deg"] == pytest.approx((before.loc[3, "heading_deg"] - 90) % 360)
    turned = math.cos(after.loc[3, "truth_rad"] - before.loc[3, "truth_rad"] - math.pi / 2)
    assert turned == pytest.approx(1.0)
    assert after.drop(index=3)["truth_rad"].equals(before.drop(index=3)["truth_rad"])
