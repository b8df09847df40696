"""Made-up run folders with known answers for the report tests, checked against a real run.

``write_fake_run`` writes what ``homebench run`` writes (config, environment, plan, job files)
for methods whose estimates are the true home direction turned by a fixed offset, with chosen
positions left without an estimate. Every metric is then known in advance.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from conftest import arena_config, run_config

from homebench.config import MetricsConfig
from homebench.evaluation.jobs import RESULT_FORMAT
from homebench.evaluation.results import build_tables, load_pairs
from homebench.geometry import Grid, angular_error, world_direction, wrap_angle

GRID = Grid((4, 5), 0.3, (-0.45, -0.6))
HEADING = 0.5
STARTED = "2024-05-06T07:08:09+00:00"


@dataclass(frozen=True)
class FakeMethod:
    """Estimates = true world direction + ``offset_deg``; none at ``missing`` positions. A
    compass (``gives_direction`` False) answers only a rotation, ``offset_deg`` off."""

    label: str
    offset_deg: float = 0.0
    missing: frozenset[tuple[int, int]] = field(default_factory=frozenset)
    home_ms: float = 1.0
    describe_ms: float = 2.0
    gives_direction: bool = True


def _rows(method: FakeMethod, goal: tuple[int, int]) -> list[dict[str, object]]:
    goal_xy = GRID.position(*goal)
    rows = []
    for i, j in GRID.indices():
        if (i, j) == goal:
            continue
        xy = GRID.position(i, j)
        truth_world = float(world_direction(xy, goal_xy))
        has = (i, j) not in method.missing and method.gives_direction
        offset = math.radians(method.offset_deg)
        estimate_world = truth_world + offset
        rows.append(
            {
                "current_i": i,
                "current_j": j,
                "rotation": 0.0,
                "heading": HEADING,
                "estimate": float(wrap_angle(estimate_world - HEADING)) if has else None,
                "estimate_world": estimate_world if has else None,
                "truth": float(wrap_angle(truth_world - HEADING)),
                "ae": float(angular_error(estimate_world, truth_world)) if has else None,
                "rotation_estimate": 0.0 if method.gives_direction else offset,
                "distance_m": float(np.hypot(*(goal_xy - xy))),
                "n_landmarks": 10 if has else 0,
                "route_views": 0,
                "score": 1.0,
                "home_ms": method.home_ms,
                "describe_ms": method.describe_ms,
                "goal_describe_ms": method.describe_ms,
                "error": None,
            }
        )
    return rows


def write_fake_run(
    folder: Path,
    methods: Sequence[FakeMethod],
    goals: Sequence[tuple[int, int]] = ((1, 2), (2, 3)),
    conditions: Sequence[str] = ("a-a",),
    name: str = "fake-run",
    world: str = "",
) -> Path:
    """Write a run folder under ``folder`` and return it. Database ``x`` has the identity
    ``db-x-<world>``: runs of another ``world`` hold other images."""
    (folder / "jobs").mkdir(parents=True, exist_ok=True)
    config = {
        "name": name,
        "output": f"runs/{name}",
        "databases": {
            alias: {"name": f"db-{alias}", "path": None, "world": None}
            for c in conditions
            for alias in c.split("-")
        },
        "conditions": list(conditions),
        "goals": [list(g) for g in goals],
        "currents": "all",
        "methods": [{"method": "fake", "label": m.label, "params": {}} for m in methods],
        "metrics": MetricsConfig().model_dump(mode="json"),
        "rotate_current": {"enabled": False, "seed": 0},
    }
    environment = {
        "config_file": "config.yaml",
        "versions": {"homebench": "0.1.0", "numpy": np.__version__},
        "host": "testhost",
        "platform": "test-platform",
        "cpu_count": 2,
        "started": STARTED,
    }
    plan = []
    for condition in conditions:
        for goal in goals:
            for method in methods:
                key = f"{condition}_{method.label}_{goal[0]}_{goal[1]}"
                plan.append({"key": key, "condition": condition, "method": method.label,
                             "goal": list(goal)})  # fmt: skip
                record = {
                    "format": RESULT_FORMAT,
                    "key": key,
                    "style": None,
                    "seed": None,
                    "condition": condition,
                    "method": method.label,
                    "method_name": "fake",
                    "params": {},
                    "compass": "none",
                    "code_version": "fake",
                    "current_database": condition.split("-")[0],
                    "goal_database": condition.split("-")[1],
                    "current_database_key": f"db-{condition.split('-')[0]}-{world}",
                    "goal_database_key": f"db-{condition.split('-')[1]}-{world}",
                    "gives_direction": method.gives_direction,
                    "goal_i": goal[0],
                    "goal_j": goal[1],
                    "goal_heading": HEADING,
                    "grid": {
                        "shape": list(GRID.shape),
                        "spacing": GRID.spacing,
                        "origin": list(GRID.origin),
                    },  # fmt: skip
                    "rows": _rows(method, goal),
                }
                (folder / "jobs" / f"{key}.json").write_text(json.dumps(record))
    (folder / "config.resolved.json").write_text(json.dumps(config))
    (folder / "environment.json").write_text(json.dumps(environment))
    (folder / "plan.json").write_text(json.dumps(plan))
    return folder


def real_arena_run(tmp_path: Path, manifest: Path) -> Path:
    """A real run of warping and min-warping on the analytic arena (two goals)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    methods = [{"method": "warping"}, {"method": "min-warping"}]
    result = run_config(tmp_path, arena_config(tmp_path, manifest, methods=methods), report=True)
    assert result.exit_code == 0, result.output
    return tmp_path / "run"


def test_fake_run_has_the_real_runs_format(tmp_path: Path, arena_manifest: Path) -> None:
    real = load_pairs(real_arena_run(tmp_path / "real", arena_manifest)).pairs
    fake = load_pairs(write_fake_run(tmp_path / "fake", [FakeMethod("m")])).pairs
    assert list(fake.columns) == list(real.columns)
    assert fake.dtypes.equals(real.dtypes)


def test_fake_run_metrics_are_the_offsets(tmp_path: Path) -> None:
    methods = [FakeMethod("ten", 10.0), FakeMethod("holes", -30.0, frozenset({(0, 0), (3, 4)}))]
    tables = build_tables(write_fake_run(tmp_path, methods), MetricsConfig())
    summary = tables.summary.set_index("method")
    assert math.isclose(summary.loc["ten", "mean_ae_deg"], 10.0, abs_tol=1e-9)
    assert math.isclose(summary.loc["holes", "median_ae_deg"], 30.0, abs_tol=1e-9)
    # (0, 0) and (3, 4) lack an estimate for both goals: 4 of 38 pairs
    assert math.isclose(summary.loc["holes", "no_estimate_share"], 4 / 38)
