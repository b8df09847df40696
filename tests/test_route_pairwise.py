"""Route homing with pairwise methods: snapshots, the leg loop, configs, jobs and the CLI.

Ground truth: straight routes of known length (the snapshot counts follow from the spacing),
grey images of known pairwise distances, and a test double that returns the true home
direction (registered only for the test, it reads the pose each image was rendered at).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from test_route_experiment import SHORT, SMALL_WORLD

from homebench.cli import main
from homebench.errors import ConfigError
from homebench.experiments.homing import MethodHomer
from homebench.experiments.robot import DriftModel, MotionLimits, Robot
from homebench.experiments.route import experiment
from homebench.experiments.route.config import RouteConfig, load_route_config
from homebench.experiments.route.experiment import (
    RouteJob,
    plan_trials,
    route_jobs,
    run_pairwise_trial,
)
from homebench.experiments.route.outbound import drive_route
from homebench.experiments.route.pairwise import PairwiseParams, Target, home_pairwise
from homebench.experiments.route.snapshots import (
    similarity_frames,
    spacing_frames,
    view_distance,
)
from homebench.geometry import Pose, home_direction, wrap_angle
from homebench.hashing import stable_hash
from homebench.methods import registry
from homebench.methods.base import HomingEstimate, ImageKind, View

#: The pose each rendered image was taken at, by the image's id (the test double reads it).
SEEN: dict[int, tuple[Pose, np.ndarray]] = {}


@dataclass(frozen=True)
class TrueDirection:
    """Test double: the true home direction and heading change (features: the view's pose)."""

    name: ClassVar[str] = "true-direction"
    image_kind: ClassVar[ImageKind] = "unfolded"

    def describe(self, view: View) -> Pose:
        return SEEN[id(view.image)][0]

    def home(self, current: Pose, goal: Pose) -> HomingEstimate:
        angle = float(home_direction(current.xy, goal.xy, current.heading))
        return HomingEstimate(angle, rotation=float(wrap_angle(current.heading - goal.heading)))


@pytest.fixture
def true_direction(monkeypatch: pytest.MonkeyPatch) -> None:
    """Register the double for this test and let it see the poses of the rendered images."""
    monkeypatch.setitem(registry._REGISTRY, TrueDirection.name, TrueDirection)
    scene_of = experiment.route_scene

    def recording_scene(config: RouteConfig) -> Any:
        scene = scene_of(config)

        def render(pose: Pose, noise_seed: int) -> np.ndarray:
            image = scene.render(pose, noise_seed)
            SEEN[id(image)] = (pose, image)  # the image kept alive: its id stays its own
            return image

        return dataclasses.replace(scene, render=render)

    monkeypatch.setattr(experiment, "route_scene", recording_scene)
    yield
    SEEN.clear()


def _config(tmp_path: Path, **changes: Any) -> RouteConfig:
    data = {**SHORT, "output": str(tmp_path / "run"), **changes}
    return RouteConfig.model_validate(data)


# --------------------------------------------------------------------------- snapshots


@pytest.mark.parametrize(
    ("length", "expected"), [(2.05, [0, 5, 10, 15, 20]), (2.0, [0, 5, 10, 15])]
)
def test_spacing_gives_a_snapshot_every_d_metres_of_a_straight_route(length, expected) -> None:
    """Steps of 0.1 m along a straight line of ``length`` m, a snapshot every 0.5 m: at 0, 0.5,
    1.0, ... below the end, floor(length / 0.5) + 1 of them (the end itself is no snapshot)."""
    robot = Robot.at(Pose(1.0, 2.0, 0.0), DriftModel(), np.random.default_rng(0))
    limits = MotionLimits(step_length=0.1, max_turn_deg=10)
    poses, odometry = drive_route(robot, [(1.0, 2.0), (1.0 + length, 2.0)], limits)
    assert len(poses) == math.ceil(length / 0.1 - 1e-9) + 1
    frames = spacing_frames(odometry, 0.5)
    assert frames == expected
    assert np.allclose(odometry[frames, 0] - 1.0, 0.5 * np.arange(len(expected)))


def test_similarity_stores_a_snapshot_when_the_view_distance_reaches_the_threshold() -> None:
    """Flat images of grey 10 k: the view distance of frames j and k is 10 |k - j|."""
    images = [np.full((4, 8), 10 * k, dtype=np.uint8) for k in range(10)]
    assert view_distance(images[7], images[3]) == pytest.approx(40.0)
    assert similarity_frames(images, 25.0) == [0, 3, 6, 9]
    assert similarity_frames(images, 10.0) == list(range(10))
    assert similarity_frames(images[:1], 10.0) == [0]


def test_view_distance_ignores_the_heading() -> None:
    rng = np.random.default_rng(1)
    image = rng.integers(0, 255, (6, 36), dtype=np.uint8)
    assert view_distance(np.roll(image, 11, axis=1), image) == pytest.approx(0.0, abs=1e-6)
    assert view_distance(255 - image, image) > 50


# --------------------------------------------------------------------------- homing


def test_a_method_with_the_true_direction_follows_the_route_home(tmp_path, true_direction):
    """The true direction at every step: home through every snapshot, ending within a step
    of home (the minimum criterion stops one view past the best and returns to it), heading
    corrected by the true rotation; far better than the drifting odometry."""
    config = _config(tmp_path, methods=[{"method": "true-direction"}])
    trial = plan_trials(config)[0]
    record = run_pairwise_trial(config, trial, "true-direction")
    summary = record["summary"]
    assert summary["visual_status"] == "reached"
    # odometry: 1.0 m at frame 10, the corner, 1.47 m at frame 19, the end (1.55 m) at 20
    assert record["snapshots"] == [0, 5, 10]
    assert record["targets"] == [10, 5, 0] and summary["legs"] == 3
    assert [leg["status"] for leg in record["legs"]] == ["reached"] * 3
    assert all(leg["miss_m"] < 0.1 for leg in record["legs"])  # within a step of each snapshot
    assert summary["visual_error_m"] < 0.05 < summary["odometry_error_m"]
    assert summary["visual_heading_error_deg"] < 2.0
    # the route's length, plus per leg at most `patience` (2) steps past the snapshot and back,
    # plus the return to the best view at home
    step = config.motion.step_length
    assert summary["visual_path_m"] < summary["driven_m"] + 3 * 2 * 2 * step + 2 * step

    oracle = _config(
        tmp_path,
        methods=[{"method": "true-direction"}],
        pairwise={"arrival": {"criterion": "oracle", "radius_m": 0.06}},
    )
    by_oracle = run_pairwise_trial(oracle, trial, "true-direction")
    assert all(leg["miss_m"] <= 0.06 for leg in by_oracle["legs"])
    assert by_oracle["summary"]["visual_error_m"] <= 0.06


# --------------------------------------------------------------------------- config, jobs


def test_klt_sector_stays_the_default_with_its_files_keys_and_resolved_config(tmp_path) -> None:
    config = _config(tmp_path)
    jobs = route_jobs(config)
    assert [job.label for job in jobs] == ["klt-sector"]
    job = jobs[0]
    assert job.result_path(tmp_path) == tmp_path / "routes" / "ell.json"
    c = config
    before = {  # the key of a trial before route runs had other methods
        "format": 1,
        "scene": c.scene_key(),
        "seed": c.seed,
        "trial": [job.trial.name, job.trial.waypoints, job.trial.heading],
        "motion": c.motion.model_dump(mode="json"),
        "drift": c.drift.model_dump(mode="json"),
        "tracker": c.tracker,
        "homing": c.homing.model_dump(mode="json"),
    }
    assert job.key == stable_hash(before)
    assert {"methods", "pairwise", "success_radius_m"}.isdisjoint(config.model_dump())
    two = _config(tmp_path, methods=[{"method": "klt-sector"}, {"method": "alv"}])
    assert two.model_dump(mode="json")["pairwise"]["snapshots"]["rule"] == "spacing"
    klt, alv = route_jobs(two)
    assert klt.key == job.key and alv.key != job.key
    assert alv.result_path(tmp_path) == tmp_path / "routes" / "alv" / "ell.json"


@pytest.mark.parametrize(
    ("methods", "message"),
    [
        ([{"method": "klt-sector", "params": {"max_corners": 9}}], "takes no params"),
        ([{"method": "klt-sector", "compass": "truth"}], "takes no params, grid or compass"),
        ([{"method": "sift"}], "homes on raw images"),
        ([{"method": "did"}], "a route robot has one view at a time"),
        ([{"method": "warping", "params": {"bogus": 1}}], "no parameter"),
        ([{"method": "nonesuch"}], "nonesuch"),
        ([{"method": "alv"}, {"method": "alv"}], "used twice"),
    ],
)
def test_bad_route_methods_name_the_entry(tmp_path, methods, message) -> None:
    path = tmp_path / "route.yaml"
    path.write_text(yaml.safe_dump({**SHORT, "output": "out", "methods": methods}))
    with pytest.raises(ConfigError, match=message):
        load_route_config(path)


TINY = {
    "kind": "route",
    "name": "tiny-pairwise",
    "world": SMALL_WORLD,
    "routes": [
        {"name": "ell", "waypoints": [[2.0, 2.5], [2.0, 3.2], [2.3, 3.2]], "lengths": [0.6, 1.0]}
    ],
    "motion": {"step_length": 0.1, "max_turn_deg": 30},
    "drift": {"heading_bias": 0.05, "scale_bias": 0.03, "translation_var": 1e-4},
    "methods": [{"method": "warping"}, {"method": "fourier-warping", "label": "fourier"}],
    "pairwise": {"snapshots": {"spacing_m": 0.3}, "max_leg_steps": 30},
}


# CI time: robot trials of every kind run through the same run_parallel; test_closed_loop_run
# compares --jobs 1 and 2 tables in the default selection
@pytest.mark.slow
def test_cli_runs_a_pairwise_route_config_alike_with_one_and_two_workers(tmp_path) -> None:
    """Every (trial, method) a job and a file; the tables of --jobs 1 and 2 are byte-equal."""
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump({**TINY, "output": str(tmp_path / "one")}))
    tables = []
    for jobs, out in ((1, "one"), (2, "two")):
        arguments = ["run", str(path), f"output={tmp_path / out}", "--jobs", str(jobs)]
        result = CliRunner().invoke(main, [*arguments, "--no-progress", "--no-report"])
        assert result.exit_code == 0, result.output
        assert "4 trial(s) computed, 0 reused" in result.output
        tables.append((tmp_path / out / "tables" / "routes.csv").read_text())
    assert tables[0] == tables[1]
    for label in ("warping", "fourier"):
        assert sorted(p.name for p in (tmp_path / "one" / "routes" / label).iterdir()) == [
            "ell-0.6m.json",
            "ell-1m.json",
        ]

    table = pd.read_csv(tmp_path / "one" / "tables" / "routes.csv")
    assert list(table["method"]) == ["warping", "fourier", "warping", "fourier"]
    assert list(table["trial"]) == ["ell-0.6m", "ell-0.6m", "ell-1m", "ell-1m"]
    # one odometry baseline per trial, whatever the method
    assert table.groupby("trial")["odometry_error_m"].nunique().tolist() == [1, 1]
    assert (table["success"] == (table["visual_error_m"] <= 0.1)).all()
    again = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert "0 trial(s) computed, 4 reused" in again.output
    job = RouteJob(load_route_config(path), plan_trials(load_route_config(path))[0], "fourier")
    assert job.method == ("fourier-warping", {})


@dataclass(frozen=True)
class NoDirection:
    """Test double: never a direction."""

    def describe(self, view: View) -> None:
        return None

    def home(self, current: None, goal: None) -> HomingEstimate:
        return HomingEstimate.none()


def test_a_leg_without_directions_drives_straight_on_then_is_lost() -> None:
    """No direction five times in a row: four straight steps, then the leg is lost."""
    from synthetic_panorama import GEOMETRY, render

    start, goal = Pose(0.5, 0.0, math.pi / 2), Pose(-0.5, 0.0, 0.0)
    target = Target(0, render(goal).image, MethodHomer(NoDirection(), None, GEOMETRY), goal)
    robot = Robot.at(start, DriftModel(), np.random.default_rng(0))
    params = PairwiseParams(arrival={"criterion": "oracle", "radius_m": 0.01}, max_no_estimate=5)
    limits = MotionLimits(step_length=0.1, max_turn_deg=30)
    look = lambda pose, k: render(pose).image  # noqa: E731
    homing = home_pairwise(robot, [target], look, limits, params)
    assert homing.status == "lost" and homing.legs[0].steps == 4 and homing.legs[0].without == 5
    assert [round(p.y, 9) for p in homing.poses] == [0.0, 0.1, 0.2, 0.3, 0.4]
