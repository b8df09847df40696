"""Route-learning methods in the robot experiments: the probes' geometry and catchment, the
training routes and displaced starts, the configs, and route and closed-loop runs from the CLI
with perfect-memory and infomax beside a pairwise method."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from test_route_experiment import SHORT, SMALL_WORLD

from homebench.cli import main
from homebench.errors import ConfigError
from homebench.experiments.closed_loop.config import TrainingRoutes, load_closed_loop_config
from homebench.experiments.memory import MemoryGuide
from homebench.experiments.route.config import RouteConfig, load_route_config
from homebench.experiments.route.experiment import RouteTrial, plan_trials, route_jobs
from homebench.experiments.route.probes import (
    Probe,
    ProbeSpec,
    catchment,
    nearest_on_path,
    path_points,
    plan_probes,
    probe_row,
    ridf_curve,
    ridf_figure,
)
from homebench.geometry import PanoramaGeometry, Pose
from homebench.imaging.rotation import rotate_view
from homebench.methods.familiarity.perfect_memory import PerfectMemory
from homebench.views import View

# --------------------------------------------------------------------------- probes


def test_path_points_drop_frames_that_only_turned() -> None:
    outbound = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1.5], [1, 1, 1.5]], dtype=np.float64)
    assert path_points(outbound).tolist() == [[0, 0], [1, 0], [1, 1]]


def test_nearest_on_path_finds_the_segment_and_its_foot() -> None:
    path = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]])
    points = np.array([[1.0, 0.5], [3.0, 1.5], [-1.0, -1.0]])
    segments, feet = nearest_on_path(path, points)
    assert segments.tolist() == [0, 1, 0]
    assert np.allclose(feet, [[1.0, 0.0], [2.0, 1.5], [0.0, 0.0]])


def test_probes_lie_beside_the_route_left_of_the_way_home() -> None:
    """Outbound from home (0, 0) along +x for 2 m, then +y for 1 m: stations every metre from
    home; the way home is -x on the first leg (left: -y) and -y on the second (left: +x)."""
    outbound = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, math.pi / 2]], np.float64)
    probes_spec = ProbeSpec(spacing_m=1.0, offsets_m=[-0.5, 0.0, 0.5])
    probes = plan_probes(outbound, probes_spec, 0)
    assert [(p.along_m, p.offset_m) for p in probes] == [
        (a, o) for a in (0.0, 1.0, 2.0, 3.0) for o in (-0.5, 0.0, 0.5)
    ]
    places = {(p.along_m, p.offset_m): (p.pose.x, p.pose.y) for p in probes}
    assert places[(1.0, 0.5)] == pytest.approx((1.0, -0.5))
    assert places[(1.0, -0.5)] == pytest.approx((1.0, 0.5))
    assert places[(3.0, 0.5)] == pytest.approx((2.5, 1.0))
    truths = {(p.along_m, p.offset_m): math.degrees(p.truth) for p in probes}
    assert abs(truths[(1.0, 0.0)]) == pytest.approx(180.0)
    assert truths[(3.0, 0.0)] == pytest.approx(-90.0)
    by_offset = {p.offset_m: p for p in probes if p.along_m == 1.0}
    assert np.allclose(by_offset[0.5].nearest, [1.0, 0.0])
    headings = [p.pose.heading for p in probes]
    assert len(set(headings)) == len(probes)  # seeded random headings, the same each time
    assert headings == [p.pose.heading for p in plan_probes(outbound, probes_spec, 0)]


def _row(offset: float, error: float | None, approach: bool | None = None) -> dict[str, Any]:
    return {"offset_m": offset, "error_deg": error, "approach": approach}


def test_catchment_is_the_last_distance_before_a_median_fails() -> None:
    rows = [
        _row(0.0, 2.0),
        _row(0.0, 60.0),
        _row(0.0, 4.0),
        _row(0.5, 10.0, True),
        _row(-0.5, 30.0, False),
        _row(1.0, 50.0, True),
        _row(-1.0, 80.0, True),
        _row(2.0, 1.0, True),  # farther: no matter, 1 m failed
        _row(2.0, None),  # not seen: not counted
    ]
    reach, table = catchment(rows, 45.0)
    assert reach == 0.5
    assert [entry["distance_m"] for entry in table] == [0.0, 0.5, 1.0, 2.0]
    assert [entry["probes"] for entry in table] == [3, 2, 2, 1]
    assert [entry["median_error_deg"] for entry in table] == [4.0, 20.0, 65.0, 1.0]
    assert table[0]["within_share"] == pytest.approx(2 / 3)
    assert table[0]["approach_share"] is None and table[1]["approach_share"] == 0.5
    assert catchment([_row(0.0, 50.0), _row(0.5, 1.0)], 45.0)[0] is None


def test_a_probe_of_a_one_view_memory_points_where_the_view_faced() -> None:
    """The memory: one view taken facing world direction 40 deg. A probe there at heading
    -100 deg sees it turned by -140 deg: the direction found is 40 deg in the world frame
    (heading + the robot-frame angle), exactly, and its RIDF is smallest at 0 relative to it."""
    geometry = PanoramaGeometry(360, 30, math.radians(40.0), math.radians(-40.0))
    rng = np.random.default_rng(2)
    image = rng.integers(0, 255, (30, 360)).astype(np.uint8)
    method = PerfectMemory()
    guide = MemoryGuide.trained(method, [View(image, geometry)], geometry)
    route = math.radians(40.0)
    probe = Probe(0.0, 0.0, Pose(0.0, 0.0, math.radians(-100.0)), route, np.zeros(2))
    seen = rotate_view(View(image, geometry), probe.pose.heading - route).image
    row = probe_row(probe, seen, method, guide.memory, geometry)
    assert row["direction_deg"] == pytest.approx(40.0, abs=1e-9)
    assert row["error_deg"] == pytest.approx(0.0, abs=1e-9) and row["approach"] is None
    relative, values = ridf_curve(row)
    assert relative.size == 90 and np.all(np.diff(relative) > 0)
    assert relative[np.argmin(values)] == pytest.approx(0.0, abs=1e-9)
    assert probe_row(probe, None, method, guide.memory, geometry)["error_deg"] is None
    figure = ridf_figure([row, {**row, "offset_m": 0.5}, {**row, "along_m": 9.0}], 0.0)
    assert len(figure.axes[0].lines) == 3  # two offsets and the route's direction


# --------------------------------------------------------------------------- training, starts


def test_training_routes_run_into_the_goal_from_equally_spaced_directions() -> None:
    goal = Pose(1.0, 2.0, math.pi / 2)
    poses = TrainingRoutes(routes=4, length_m=0.3, spacing_m=0.1).poses(goal)
    assert len(poses) == 12
    first = poses[:3]  # straight ahead of the goal's heading (+y), far end first
    assert [p.x for p in first] == pytest.approx([1.0] * 3)
    assert [p.y for p in first] == pytest.approx([2.3, 2.2, 2.1])
    assert all(p.heading == pytest.approx(-math.pi / 2) for p in first)  # facing the goal
    second = poses[3]  # a quarter turn ccw: -x
    assert (second.x, second.y, second.heading) == pytest.approx((0.7, 2.0, 0.0))


def test_a_displaced_start_is_carried_left_of_the_last_segment() -> None:
    trial = RouteTrial("t", "r", 2.0, ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0)), 0.0, 0.3)
    start = trial.homing_start(Pose(1.0, 1.0, 0.5))
    assert (start.x, start.y, start.heading) == pytest.approx((0.7, 1.0, 0.5))
    assert RouteTrial("t", "r", 2.0, trial.waypoints, 0.0, 0.0).homing_start(start) == start


# --------------------------------------------------------------------------- configs


def _route_config(tmp_path: Path, **changes: Any) -> RouteConfig:
    return RouteConfig.model_validate({**SHORT, "output": str(tmp_path / "run"), **changes})


def test_route_config_keys_and_resolved_config(tmp_path: Path) -> None:
    """``familiarity`` is resolved (and keyed) only when a method learns a route; the
    displacements name the trials."""
    pairwise = _route_config(tmp_path, methods=[{"method": "warping"}])
    assert "familiarity" not in pairwise.model_dump()
    routes = [{**SHORT["routes"][0], "displacements_m": [0.0, -0.2]}]
    both = _route_config(
        tmp_path, routes=routes, methods=[{"method": "warping"}, {"method": "perfect-memory"}]
    )
    assert both.model_dump()["familiarity"]["near_home_m"] == 1.0
    assert [t.name for t in plan_trials(both)] == ["ell-d0m", "ell-d-0.2m"]
    warping, memory = route_jobs(both)[:2]
    assert (warping.label, memory.label) == ("warping", "perfect-memory")
    changed = _route_config(
        tmp_path,
        routes=routes,
        methods=[{"method": "warping"}, {"method": "perfect-memory"}],
        familiarity={"near_home_m": 0.5},
    )
    again = route_jobs(changed)[:2]
    assert again[0].key == warping.key and again[1].key != memory.key


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ({"method": "infomax", "compass": "truth"}, "takes no compass"),
        ({"method": "perfect-memory", "params": {"image_size": [0, 3]}}, "image_size"),
        ({"method": "infomax", "params": {"bogus": 1}}, "no parameter"),
    ],
)
def test_bad_memory_entries_name_the_entry(tmp_path: Path, entry, message) -> None:
    route = tmp_path / "route.yaml"
    route.write_text(yaml.safe_dump({**SHORT, "output": "out", "methods": [entry]}))
    with pytest.raises(ConfigError, match=rf"methods\.0.*{message}"):
        load_route_config(route)
    loop = tmp_path / "loop.yaml"
    loop.write_text(yaml.safe_dump({**CLOSED_LOOP, "output": "out", "methods": [entry]}))
    with pytest.raises(ConfigError, match=rf"methods\.0.*{message}"):
        load_closed_loop_config(loop)


# --------------------------------------------------------------------------- runs

ROUTE = {
    "kind": "route",
    "name": "tiny-familiarity",
    "world": SMALL_WORLD,
    "routes": [
        {"name": "ell", "waypoints": [[2.0, 2.5], [2.0, 3.0], [2.2, 3.0]]},
    ],
    "motion": {"step_length": 0.1, "max_turn_deg": 30},
    "drift": {"heading_bias": 0.05, "scale_bias": 0.03, "translation_var": 1e-4},
    "methods": [{"method": "perfect-memory"}, {"method": "infomax"}, {"method": "warping"}],
    "pairwise": {"snapshots": {"spacing_m": 0.3}, "max_leg_steps": 20},
    "familiarity": {
        "near_home_m": 0.3,
        "probes": {"spacing_m": 0.35, "offsets_m": [-0.2, 0.0, 0.2]},
    },
}


def test_a_route_run_follows_and_probes_with_both_families(tmp_path: Path) -> None:
    """One trial homed by perfect-memory, infomax and warping from the same drive: the memory
    methods' probe rows and catchment tables, the pairwise method's none; the report pairs the
    two families on the trial. The median error on
    the route is small (measured 0.6 deg for both; infomax takes the route's other leg at its
    end, 0.2 m past the corner)."""
    path = tmp_path / "route.yaml"
    path.write_text(yaml.safe_dump({**ROUTE, "output": str(tmp_path / "run")}))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress"])
    assert result.exit_code == 0, result.output
    assert "3 trial(s) computed, 0 reused" in result.output
    tables = tmp_path / "run" / "tables"
    routes = pd.read_csv(tables / "routes.csv").set_index("method")
    assert list(routes.index) == ["perfect-memory", "infomax", "warping"]
    assert routes["odometry_error_m"].nunique() == 1  # the same drive and baseline
    assert routes.loc["warping", ["catchment_m", "probe_error_on_route_deg"]].isna().all()
    probes = pd.read_csv(tables / "route_probes.csv")
    assert set(probes["method"]) == {"perfect-memory", "infomax"}
    assert len(probes) == 2 * 3 * 3 and probes["seen"].all()  # stations 0, 0.35, 0.7 m
    distances = pd.read_csv(tables / "route_catchment.csv")
    assert list(distances["distance_m"]) == [0.0, 0.2, 0.0, 0.2]
    for method in ("perfect-memory", "infomax"):
        assert routes.loc[method, "probe_error_on_route_deg"] < 10
        assert routes.loc[method, "visual_status"] in {"reached", "steps", "lost"}
    report = tmp_path / "run" / "report"
    assert (report / "report.pdf").stat().st_size > 0
    paired = pd.read_csv(report / "tables" / "routes_paired.csv")
    pairs = set(zip(paired["A"], paired["B"], strict=True))
    assert {("perfect-memory", "warping"), ("infomax", "warping")} <= pairs
    assert (paired["trials"] == 1).all()
    # one RIDF figure per memory method (the station halfway along), none for warping
    ridfs = sorted(path.name for path in (report / "figures").glob("ridf_*.png"))
    assert [name.split("_")[1] for name in ridfs] == ["infomax", "perfect-memory"]
    # seed 000's findings are klt-sector's: a run without it says so (it crashed)
    result = CliRunner().invoke(main, ["findings", str(tmp_path / "run")])
    assert result.exit_code == 2, result.output
    assert "klt-sector" in result.output and "perfect-memory" in result.output


CLOSED_LOOP = {
    "kind": "closed-loop",
    "name": "tiny-memory",
    "world": {"seed": 0, "grid": {"shape": [5, 5], "spacing": 0.3}, "unfolded": {"width": 96}},
    "methods": [{"method": "perfect-memory"}, {"method": "infomax"}, {"method": "warping"}],
    "controls": ["truth"],
    "goals": [{"grid": [2, 2]}],
    "starts": {"spacing": 0.8},
    "motion": {"step_length": 0.1, "max_turn_deg": 30, "success_radius": 0.15},
    "training": {"routes": 4, "length_m": 0.8, "spacing_m": 0.2},
}


@pytest.mark.slow  # CI time: the route run above drives the same methods
def test_a_closed_loop_run_accepts_route_learning_methods(tmp_path: Path) -> None:
    """The memory methods learn the training routes into the goal and home from the same
    starts as warping; the paired table compares all three."""
    path = tmp_path / "loop.yaml"
    path.write_text(yaml.safe_dump({**CLOSED_LOOP, "output": str(tmp_path / "run")}))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv").set_index("method")
    assert list(summary.index) == ["perfect-memory", "infomax", "warping", "truth"]
    assert summary["trials"].nunique() == 1
    assert summary.loc["perfect-memory", "success"] >= 0.5
    paired = pd.read_csv(tmp_path / "run" / "tables" / "paired.csv")
    assert {"perfect-memory", "infomax"} <= set(paired["method_a"]) | set(paired["method_b"])
    resolved = (tmp_path / "run" / "config.resolved.json").read_text()
    assert '"training"' in resolved
