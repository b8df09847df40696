"""Recorded routes (Brains on Board route folders) replayed in route runs: the scene shows the
recorded image nearest to the robot turned to its heading, ``waypoints: recorded`` follows the
recorded poses, and a route run over a hand-written route folder homes with both families
(a pairwise method and a route-learning one) and writes its report.

The folder is tests/bob_folders.py's: ten poses on an arc of radius 1 m (0 to 90 deg around the
arena centre), each image rendered exactly at its pose and heading and laid out as BoB's Ant
World renders, written as BoB's recorders write them (mm, compass headings, spaces after
commas, OpenCV's metadata)."""

from __future__ import annotations

import math
import os
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
from bob_folders import ROUTE_POSES, WIDTH, bob_image, route_poses, write_grid, write_route
from click.testing import CliRunner
from conftest import run_config

from homebench.cli import main
from homebench.config import UnfoldConfig
from homebench.data.bob import open_bob
from homebench.data.synth.world import PoseError
from homebench.errors import ConfigError
from homebench.experiments.route.config import RouteConfig, RouteSpec
from homebench.experiments.route.experiment import plan_trials
from homebench.experiments.scene import open_scene, posed_scene, sparsest_spacing
from homebench.geometry import Pose

#: Chord between neighbouring recorded poses: 1 m x 2 sin(90 deg / 9 / 2).
STEP_M = 2.0 * math.sin(math.radians(90.0 / (ROUTE_POSES - 1) / 2.0))


@pytest.fixture(scope="module")
def route(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_route(tmp_path_factory.mktemp("bob") / "arena-route")


def _pose(k: int, turn_deg: float = 0.0) -> Pose:
    """Recorded pose k in homebench's frame (heading ccw from +x), turned ccw by ``turn_deg``."""
    x, y, compass = route_poses()[k]
    return Pose(x / 1000.0, y / 1000.0, math.radians(90.0 - compass + turn_deg))


def _image(k: int) -> np.ndarray:
    """Recorded image k, as BoB's renderer lays it out."""
    x, y, compass = route_poses()[k]
    return bob_image(x, y, compass)


def test_the_scene_shows_the_nearest_recorded_image_turned_to_the_pose(route: Path) -> None:
    """At a recorded pose the scene gives that image; turned a quarter, the image rolled by a
    quarter of its columns (a ccw turn: the world moves to lower azimuths, which BoB's images
    show further right); near a pose, that pose's image; beyond the sparsest spacing, no
    image."""
    db = open_bob(route)
    scene = posed_scene(db, UnfoldConfig())
    assert scene.grid is None and scene.geometry == db.camera
    for k in (0, 4, 9):
        recorded = _image(k)
        assert np.array_equal(scene.render(_pose(k), 0), recorded)
        turned = scene.render(_pose(k, 90.0), 0)
        assert np.array_equal(turned, np.roll(recorded, WIDTH // 4, axis=1))
    near = _pose(3)
    assert np.array_equal(scene.render(Pose(near.x + 0.03, near.y, near.heading), 0), _image(3))
    assert sparsest_spacing(scene.recorded.xy) == pytest.approx(STEP_M, abs=1e-4)
    with pytest.raises(PoseError, match="farther than its sparsest spacing"):
        scene.check_pose(Pose(0.3, 0.3, 0.0))  # 0.58 m from the arc
    wider = posed_scene(open_bob(route), UnfoldConfig(), reach_m=0.6)  # recorded_reach_m
    inside = Pose(0.5 * _pose(4).x, 0.5 * _pose(4).y, _pose(4).heading)  # 0.5 m in from image 4
    assert np.array_equal(wider.render(inside, 0), _image(4))
    with pytest.raises(PoseError, match="recorded_reach_m") as outside:
        wider.check_pose(Pose(-0.5, -0.5, 0.0))
    assert outside.value.fault == "outside"  # beyond the recording: no collision with anything


def test_recorded_waypoints_follow_the_recording_in_metres(route: Path) -> None:
    config = RouteConfig.model_validate(
        {
            "kind": "route", "output": "out", "database": str(route),
            "routes": [{"name": "arc", "waypoints": "recorded", "lengths": [0.5, 1.5]}],
        }
    )  # fmt: skip
    # the resolved config reads back (it held the default world beside the database: refused)
    assert RouteConfig.model_validate(config.model_dump(mode="json")) == config
    trials = plan_trials(config)
    assert [t.name for t in trials] == ["arc-0.5m", "arc-1.5m"]
    whole = np.array([(x / 1000.0, y / 1000.0) for x, y, _ in route_poses()])
    kept = trials[1].waypoints  # the recorded poses, then where 1.5 m ends on the last chord
    assert np.allclose(kept[:-1], whole[: len(kept) - 1])
    assert len(kept) == ROUTE_POSES and math.dist(kept[-1], whole[-1]) < STEP_M
    assert trials[0].waypoints[0] == pytest.approx((1.0, 0.0))
    along_first_chord = math.radians(90.0 + 90.0 / 18)
    assert trials[0].heading == pytest.approx(along_first_chord, abs=1e-4)


@pytest.mark.parametrize(
    ("routes", "message"),
    [
        ([{"name": "arc", "waypoints": "recorded", "lengths": [2.0]}], "exceeds the route's"),
        (
            [{"name": "arc", "waypoints": "recorded", "frame": "grid"}],
            "recorded waypoints are the database's poses",
        ),
    ],
)
def test_recorded_routes_that_cannot_be_replayed_say_why(
    route: Path, tmp_path: Path, routes: list, message: str
) -> None:
    config = {"kind": "route", "output": str(tmp_path / "run"), "database": str(route)}
    result = run_config(tmp_path, {**config, "routes": routes})
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not (tmp_path / "run" / "routes").exists()


def test_recorded_waypoints_need_a_recording(tmp_path: Path) -> None:
    route = {"name": "arc", "waypoints": "recorded"}
    with pytest.raises(ValueError, match="give 'database'"):
        RouteConfig.model_validate({"kind": "route", "output": "out", "routes": [route]})
    grid = write_grid(tmp_path / "arena-grid")
    config = RouteConfig.model_validate(
        {"kind": "route", "output": "out", "database": str(grid), "routes": [route]}
    )
    with pytest.raises(ConfigError, match="is a grid"):
        plan_trials(config)
    # a grid folder keeps its grid scene: nearest grid images
    assert open_scene(config.world, str(grid), None, UnfoldConfig()).grid is not None
    # the resolved config of a route run on any database reads back: it held the default
    # world beside the database, refused on reading ('homebench run' then exited 2)
    listed = {"name": "ell", "waypoints": [[-0.6, -0.45], [0.3, -0.45]]}
    on_grid = config.model_copy(update={"routes": [RouteSpec.model_validate(listed)]})
    assert RouteConfig.model_validate(on_grid.model_dump(mode="json")) == on_grid


def test_a_closed_loop_run_on_a_recording_says_it_needs_a_grid(route: Path, tmp_path: Path) -> None:
    config = {
        "kind": "closed-loop", "output": str(tmp_path / "run"), "database": str(route),
        "methods": [{"method": "warping"}], "controls": ["truth"],
        "goals": [{"grid": [0, 0]}], "starts": {"spacing": 0.5},
    }  # fmt: skip
    result = run_config(tmp_path, config)
    assert result.exit_code == 2, result.output
    assert "is a recording" in result.output and "waypoints: recorded" in result.output


def test_a_route_run_replays_a_recorded_route_with_both_families(
    route: Path, tmp_path: Path
) -> None:
    """The recorded arc driven out and homed by warping (snapshots) and perfect-memory (every
    outbound view) from the same drive, probed along the route; the report pairs the two.
    Every view is a recorded image; a trial ends where the robot arrives or leaves the
    recording's reach (near home it may overshoot the first pose: outside), so the test
    checks the drive, the probes and the report, not arrival."""
    config = {
        "kind": "route",
        "name": "recorded-arc",
        "output": str(tmp_path / "run"),
        "database": str(route),
        "routes": [{"name": "arc", "waypoints": "recorded"}],
        "motion": {"step_length": 0.1, "max_turn_deg": 30},
        "drift": {"heading_bias": 0.02, "translation_var": 1e-5},
        "methods": [{"method": "perfect-memory"}, {"method": "warping"}],
        "pairwise": {"snapshots": {"spacing_m": 0.35}, "max_leg_steps": 20},
        "familiarity": {"near_home_m": 0.3, "probes": {"spacing_m": 0.5, "offsets_m": [0.0]}},
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "2 trial(s) computed, 0 reused" in result.output
    tables = tmp_path / "run" / "tables"
    routes = pd.read_csv(tables / "routes.csv").set_index("method")
    assert list(routes.index) == ["perfect-memory", "warping"]
    assert routes["odometry_error_m"].nunique() == 1  # the same drive and baseline
    assert routes["length_m"].iloc[0] == pytest.approx(math.pi / 2, abs=0.01)
    probes = pd.read_csv(tables / "route_probes.csv")
    assert probes["seen"].all() and (probes["method"] == "perfect-memory").all()
    # on the route, perfect memory points along it (the views are the recorded images)
    assert routes.loc["perfect-memory", "probe_error_on_route_deg"] < 10
    report = CliRunner().invoke(main, ["report", str(tmp_path / "run")])
    assert report.exit_code == 0, report.output
    assert (tmp_path / "run" / "report" / "report.pdf").stat().st_size > 0
    paired = pd.read_csv(tmp_path / "run" / "report" / "tables" / "routes_paired.csv")
    assert ("perfect-memory", "warping") in set(zip(paired["A"], paired["B"], strict=True))


@pytest.mark.parametrize("kind", ["route", "grid"])
def test_an_edited_database_gives_route_and_closed_loop_trials_new_keys(
    tmp_path: Path, kind: str
) -> None:
    """A trial's key named its database by locator and path only, so a run after an image or
    a pose was corrected reused the trials homed on the old ones. Its key now holds what the
    database holds; the run that starts reads the database afresh."""
    from homebench.experiments.closed_loop.config import ClosedLoopConfig
    from homebench.experiments.closed_loop.experiment import scene_key
    from homebench.experiments.route.experiment import route_jobs
    from homebench.experiments.scene import forget_databases

    folder = (write_route if kind == "route" else write_grid)(tmp_path / "db")
    waypoints = "recorded" if kind == "route" else [[0.0, 0.0], [0.3, 0.0]]
    config = RouteConfig.model_validate({
        "kind": "route", "output": str(tmp_path / "out"), "database": str(folder),
        "routes": [{"name": "r", "waypoints": waypoints, "frame": "world"}],
        "methods": [{"method": "warping"}],
    })  # fmt: skip
    loop = None
    if kind == "grid":
        loop = ClosedLoopConfig.model_validate({
            "kind": "closed-loop", "output": str(tmp_path / "loop"), "database": str(folder),
            "methods": [{"method": "warping"}], "goals": [{"grid": [2, 2]}],
            "starts": {"random": 3, "seed": 1},
        })  # fmt: skip

    def keys() -> list[object]:
        forget_databases()  # as a run does when it starts
        found: list[object] = [job.key for job in route_jobs(config)]
        return found + ([] if loop is None else [scene_key(loop, "database")])

    before = keys()
    assert before == keys()  # nothing changed: the same keys
    image = sorted(folder.glob("*.png"))[1]
    pixels = cv2.imread(str(image), cv2.IMREAD_UNCHANGED)
    cv2.imwrite(str(image), 255 - pixels)  # the same size, other pixels
    _later(image)
    edited = keys()
    assert all(new != old for new, old in zip(edited, before, strict=True))
    listing = folder / "database_entries.csv"
    lines = listing.read_text().splitlines()
    fields = lines[2].split(",")
    fields[3] = f" {float(fields[3]) + 10.0:g}"  # a corrected heading of the second image
    lines[2] = ",".join(fields)
    listing.write_text("\n".join(lines) + "\n")
    _later(listing)
    assert all(new != old for new, old in zip(keys(), edited, strict=True))


def _later(path: Path) -> None:
    """Date ``path`` a second on, as a user's edit would be: files are known by their size and
    modification time, and this test edits faster than the file system's clock ticks."""
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))
