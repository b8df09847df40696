"""Closed-loop homing: config errors, the truth and random controls, how a trial ends, the
catchment arithmetic. Ground truth: the true poses of the simulated robot; a trial's end is
decided by the robot's exact kinematics (no motion noise unless a test adds it)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner

from homebench.cli import main
from homebench.data.synth.world import PoseError
from homebench.experiments.closed_loop.config import ClosedLoopConfig, ClosedLoopMotion
from homebench.experiments.closed_loop.experiment import (
    plan_trials,
    run_closed_loop_experiment,
)
from homebench.experiments.closed_loop.homers import TruthHomer
from homebench.experiments.closed_loop.loop import run_loop
from homebench.experiments.closed_loop.tables import catchment_area, catchment_map
from homebench.experiments.robot import DriftModel, Robot
from homebench.geometry import Pose

#: A small-image world; the starts: a 7 x 7 lattice 0.2 m apart around the goal, the capture
#: grid's extent (1.2 m square) in the middle of the posters room, clear of its objects.
TINY_WORLD = {"seed": 0, "grid": {"shape": [5, 5], "spacing": 0.3}, "unfolded": {"width": 48}}
CONTROLS_ONLY = {
    "kind": "closed-loop",
    "world": TINY_WORLD,
    "controls": ["truth", "random"],
    "goals": [{"grid": [2, 2]}],
    "starts": {"spacing": 0.2},
    "motion": {"step_length": 0.1, "max_turn_deg": 30, "success_radius": 0.15},
}


def _config(tmp_path: Path, **changes: object) -> ClosedLoopConfig:
    data = {**CONTROLS_ONLY, "output": str(tmp_path / "run"), **changes}
    return ClosedLoopConfig.model_validate(data)


def _run(config: ClosedLoopConfig, tmp_path: Path) -> pd.DataFrame:
    run_closed_loop_experiment(config, tmp_path / "c.yaml", jobs=1, show_progress=False)
    return pd.read_csv(Path(config.output) / "tables" / "trials.csv")


# --------------------------------------------------------------------------- config errors


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"mothods": []}, "did you mean 'methods'"),
        ({"methods": [{"method": "sift"}]}, "homes on raw images"),
        ({"methods": [{"method": "did"}]}, "neighbouring grid positions"),
        ({"methods": [{"method": "warping", "label": "truth"}]}, "'truth' used twice"),
        ({"methods": [{"method": "warping", "params": {"n_rhoo": 3}}]}, "n_rho"),
        ({"starts": {"spacing": 0.2, "region": [1, 1, 0, 2]}}, "is not \\[x_min"),
        ({"goals": [{"at": [1, 1], "grid": [0, 0]}]}, "exactly one of"),
        ({"motion": {"budget_factor": None}}, "path budget"),
        ({"database": "synth-original"}, "not both"),
        ({"goals": [{"at": [-5.0, 1.0]}]}, "goals\\[0\\] \\(posters\\).*outside the room"),
    ],
)
def test_bad_configs_fail_in_one_line_and_write_nothing(
    tmp_path: Path, change: dict, message: str
) -> None:
    path = tmp_path / "closed.yaml"
    path.write_text(yaml.safe_dump({**CONTROLS_ONLY, "output": str(tmp_path / "run"), **change}))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert result.exit_code != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and re.search(message, lines[0]), lines
    assert not (tmp_path / "run").exists()


# --------------------------------------------------------------------------- the controls


@pytest.fixture(scope="module")
def controls(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    """The trials of both controls from the same 40 starts (one run: workers start once)."""
    tmp_path = tmp_path_factory.mktemp("controls")
    return _run(_config(tmp_path), tmp_path)


def test_truth_reaches_home_from_every_start_on_a_straight_line(controls: pd.DataFrame) -> None:
    """Without noise the truth control turns on the spot, then drives straight: the path of
    a success is a whole number of steps covering start distance - success radius, so its
    ratio lies in [1, 1 + step / (d - r))."""
    trials = controls[controls["method"] == "truth"]
    assert len(trials) == 40  # 49 lattice starts minus the goal and its 8 neighbours (< 0.3 m)
    assert trials["success"].all()
    d, r, step = trials["start_distance_m"], 0.15, 0.1
    assert (trials["path_ratio"] >= 1 - 1e-9).all()
    assert (trials["path_ratio"] < 1 + step / (d - r) + 1e-9).all()
    assert (trials["final_distance_m"] <= r).all()


def test_random_control_almost_never_homes(controls: pd.DataFrame) -> None:
    """The random control is a random walk (a step moves only when the draw lies within the
    30 deg turn limit, 1 in 6). The bound: the success disc (0.07 m^2) is 5 % of the 1.44 m^2
    start region, and a walk that has spread over the region by the end of its budget
    (3 x the start distance) ends in it about that often, more often from nearby starts; 10 %
    allows for those. Seeded: 4 of 40 (the truth control: 40 of 40)."""
    trials = controls[controls["method"] == "random"]
    assert int(trials["success"].sum()) == 4
    assert trials["success"].mean() <= 0.1


# --------------------------------------------------------------------------- how a trial ends


class _Ahead:
    """A homer that always says: straight ahead."""

    sees = False

    def direction(self, pose: Pose, image: object) -> float | None:
        return 0.0


class _Blind:
    sees = False

    def direction(self, pose: Pose, image: object) -> float | None:
        return None


def _wall_at(x: float):
    def check(pose: Pose) -> None:
        if pose.x > x:
            raise PoseError(f"beyond the wall at x = {x}")

    return check


def _robot(pose: Pose) -> Robot:
    return Robot.at(pose, DriftModel(), np.random.default_rng(0))


def _never(image_pose: Pose) -> np.ndarray:
    raise AssertionError("the controls see nothing")


def test_a_collision_ends_the_trial_at_the_wall() -> None:
    motion = ClosedLoopMotion(step_length=0.125)
    goal = Pose(2.0, 0.0)
    result = run_loop(_robot(Pose(0.0, 0.0, 0.0)), goal, TruthHomer(goal), _never,
                      _wall_at(1.0), motion)  # fmt: skip
    assert result.outcome == "collision"
    assert result.steps == 9 and result.poses[-1].x == pytest.approx(1.125)


def test_the_budget_gives_up() -> None:
    """Facing away from a goal 1 m off and driving straight on: 24 steps of 0.125 m make
    the 3 m budget."""
    motion = ClosedLoopMotion(step_length=0.125, budget_factor=3.0)
    result = run_loop(_robot(Pose(0.0, 0.0, math.pi)), Pose(1.0, 0.0), _Ahead(), _never,
                      _wall_at(10.0), motion)  # fmt: skip
    assert result.outcome == "budget"
    assert result.steps == 24 and result.path == pytest.approx(3.0)


def test_an_absolute_budget_caps_the_factor() -> None:
    motion = ClosedLoopMotion(step_length=0.125, budget_factor=3.0, budget_m=1.0)
    result = run_loop(_robot(Pose(0.0, 0.0, math.pi)), Pose(1.0, 0.0), _Ahead(), _never,
                      _wall_at(10.0), motion)  # fmt: skip
    assert result.outcome == "budget" and result.steps == 8


def test_no_estimate_stops_or_drives_on() -> None:
    start, goal = Pose(0.0, 0.0, math.pi), Pose(1.0, 0.0)
    stop = ClosedLoopMotion(step_length=0.125, no_estimate="stop")
    stopped = run_loop(_robot(start), goal, _Blind(), _never, _wall_at(10.0), stop)
    assert (stopped.outcome, stopped.steps, stopped.no_estimates) == ("no_estimate", 0, 1)
    drive_on = stop.model_copy(update={"no_estimate": "continue", "max_steps": 5})
    driven = run_loop(_robot(start), goal, _Blind(), _never, _wall_at(10.0), drive_on)
    assert (driven.outcome, driven.steps, driven.no_estimates) == ("steps", 5, 5)
    assert driven.poses[-1].x == pytest.approx(-0.625)


# --------------------------------------------------------------------------- catchment


def test_catchment_area_is_cells_times_cell_area() -> None:
    """A 3 x 4 lattice of 0.2 m cells (0.04 m^2) with 5 successful starts: 0.2 m^2."""
    cells = [(c, r) for r in range(3) for c in range(4)]
    success = [c + r < 2 for c, r in cells] + []  # (0,0), (1,0), (0,1): 3 cells
    success[cells.index((3, 2))] = True
    success[cells.index((2, 2))] = True
    frame = pd.DataFrame({
        "cell_i": [c for c, _ in cells], "cell_j": [r for _, r in cells],
        "success": success, "cell_area_m2": 0.04,
    })  # fmt: skip
    assert catchment_area(frame["success"], frame["cell_area_m2"]) == pytest.approx(0.2)
    expected = np.array([[1, 1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 1]], dtype=float)
    np.testing.assert_array_equal(catchment_map(frame), expected)
    missing = catchment_map(frame.drop(index=[0]))
    assert np.isnan(missing[0, 0]) and np.nansum(missing) == 4


def test_starts_are_the_same_for_every_method_and_seeded(tmp_path: Path) -> None:
    config = _config(tmp_path, starts={"random": 20, "seed": 3})
    trials = plan_trials(config)
    truth = [(t.start.x, t.start.y, t.start.heading) for t in trials if t.label == "truth"]
    random = [(t.start.x, t.start.y, t.start.heading) for t in trials if t.label == "random"]
    assert truth == random and len(truth) == len({s[:2] for s in truth})
    again = [(t.start.x, t.start.y, t.start.heading) for t in plan_trials(config)]
    assert again == [(t.start.x, t.start.y, t.start.heading) for t in trials]
    area = 1.2 * 1.2 / 20  # each random start stands for region area / starts drawn
    assert all(t.start.area == pytest.approx(area) for t in trials)


def test_a_fixed_start_heading_replaces_the_seeded_ones(tmp_path: Path) -> None:
    config = _config(tmp_path, starts={"spacing": 0.4, "heading_deg": 90.0})
    assert {t.start.heading for t in plan_trials(config)} == {math.pi / 2}


class _Ahead4:
    """A method stub: its features are the image, its answer always "straight ahead"."""

    def describe(self, view):  # type: ignore[no-untyped-def]
        return view.image

    def home(self, current, goal):  # type: ignore[no-untyped-def]
        from homebench.methods.base import HomingEstimate

        return HomingEstimate(0.0 if np.array_equal(current, goal) else None)


def test_a_compass_turns_the_view_and_the_answer_back() -> None:
    """The robot faces +y (heading pi/2), the goal snapshot +x (heading 0). With a compass
    it turns its view by -pi/2 (a quarter of the 8 columns), which then equals the goal's, and
    the method's "ahead" (+x in the aligned frame) is -pi/2 in the robot's frame."""
    from homebench.experiments.closed_loop.homers import MethodHomer
    from homebench.experiments.scene import turned
    from homebench.geometry import PanoramaGeometry
    from homebench.views import View

    geometry = PanoramaGeometry.square_pixels(8, 0.2, -0.2)
    goal = np.arange(8, dtype=np.uint8)[None].repeat(2, axis=0)
    seen = turned(View(goal, geometry), math.pi / 2)  # the goal's view from heading pi/2
    pose = Pose(0.0, 0.0, math.pi / 2)
    with_compass = MethodHomer(_Ahead4(), goal, geometry, compass="truth", goal_heading=0.0)
    assert with_compass.direction(pose, seen) == pytest.approx(-math.pi / 2)
    assert MethodHomer(_Ahead4(), goal, geometry).direction(pose, seen) is None


def test_the_visual_compass_finds_the_turn_from_the_two_images() -> None:
    from homebench.experiments.closed_loop.homers import MethodHomer
    from homebench.experiments.scene import turned
    from homebench.geometry import PanoramaGeometry
    from homebench.views import View

    geometry = PanoramaGeometry.square_pixels(72, 0.4, -0.4)
    goal = np.random.default_rng(3).integers(0, 256, (geometry.height, 72), dtype=np.uint8)
    seen = turned(View(goal, geometry), math.pi / 2)
    homer = MethodHomer(_Ahead4(), goal, geometry, "visual", goal_view=View(goal, geometry))
    assert homer.direction(Pose(0.0, 0.0, 1.0), seen) == pytest.approx(-math.pi / 2)


def test_views_snap_to_the_lattice_and_come_from_the_caches(tmp_path: Path) -> None:
    """Poses in one lattice cell share one render (memory), a second process's views come
    from the disk cache, a zero-byte bound writes nothing; headings turn by whole columns."""
    from homebench.experiments.closed_loop.views import LatticeViews
    from homebench.experiments.scene import Scene
    from homebench.geometry import PanoramaGeometry

    geometry = PanoramaGeometry.square_pixels(8, 0.2, -0.2)
    rendered: list[Pose] = []

    def render(pose: Pose, noise_seed: int) -> np.ndarray:
        rendered.append(pose)
        row = np.arange(8, dtype=np.uint8) + np.uint8(len(rendered))
        return row[None].repeat(geometry.height, axis=0)

    scene = Scene(geometry, render, lambda pose: None, (0.0, 0.0))
    views = LatticeViews(scene, 0.02, tmp_path / "v", 1e9, 4, 0)
    first = views.see(Pose(0.011, 0.029, 0.0))
    turned = views.see(Pose(0.025, 0.015, math.pi / 2))  # same node (1, 1), a quarter turn
    assert rendered == [Pose(0.02, 0.02, 0.0)] and views.node(Pose(0.011, 0.029)) == (1, 1)
    assert any(np.array_equal(turned, np.roll(first, s, axis=1)) for s in (2, -2))
    other = LatticeViews(scene, 0.02, tmp_path / "v", 1e9, 4, 0)
    np.testing.assert_array_equal(other.see(Pose(0.02, 0.02, 0.0)), first)
    assert other.rendered == 0 and len(rendered) == 1
    bounded = LatticeViews(scene, 0.02, tmp_path / "w", 0.0, 0, 0)
    bounded.see(Pose(0.5, 0.5, 0.0))
    assert not list((tmp_path / "w").glob("*.png"))
