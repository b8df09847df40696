"""The warping family on rendered views of a generated world (not the analytic arena).

Tolerances: the generated room breaks warping's equal-distance assumption (walls 1.5-4 m away,
furniture nearer), so single pairs 0.3-0.6 m from the goal are held to 35 degrees — well inside
the 90 degrees that would still bring a robot nearer, and far from what a mirrored axis or a
flipped sign gives (about 180 degrees on one of the four axis directions).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import run_config

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import build_world
from homebench.geometry import Pose, angular_error, home_direction
from homebench.imaging.rotation import rotate_view
from homebench.methods import registry
from homebench.methods.base import View

SPEC = WorldSpec(seed=0, grid={"shape": [5, 5]})
GOAL = SPEC.to_grid().position(2, 2)


def _view(x: float, y: float, heading: float) -> View:
    image = build_world(SPEC).render(Pose(x, y, heading), noise_seed=1)["unfolded"]
    return View(image, SPEC.unfolded.geometry())


@pytest.mark.parametrize("method", ["warping", "min-warping"])
@pytest.mark.parametrize("heading", [0.0, 1.0])
@pytest.mark.parametrize("offset", [(0.3, 0), (-0.3, 0), (0, 0.3), (0, -0.3), (0.6, 0), (0, -0.6)])
def test_home_direction_along_both_axes(method: str, heading: float, offset: tuple) -> None:
    model = registry.create(method)
    goal = model.describe(_view(GOAL[0], GOAL[1], heading))
    current_xy = (GOAL[0] + offset[0], GOAL[1] + offset[1])
    view = _view(*current_xy, heading)
    truth = home_direction(current_xy, GOAL, heading)
    estimate = model.home(model.describe(view), goal)
    assert estimate.angle is not None
    assert math.degrees(angular_error(estimate.angle, truth)) < 35


@pytest.mark.parametrize("method", ["warping", "min-warping"])
def test_rotated_current_view_gives_rotation_and_direction(method: str) -> None:
    model = registry.create(method)
    goal = model.describe(_view(GOAL[0], GOAL[1], 0.0))
    current_xy = (GOAL[0] + 0.3, GOAL[1] - 0.3)
    turn = 2 * math.pi * 90 / 360  # 90 columns of the 360-column panorama
    view = rotate_view(_view(*current_xy, 0.0), turn)
    estimate = model.home(model.describe(view), goal)
    # the turned robot's heading is +turn: its home direction turns by -turn
    truth = home_direction(current_xy, GOAL, turn)
    assert math.degrees(angular_error(estimate.angle, truth)) < 35
    assert math.degrees(angular_error(estimate.rotation, turn)) < 6


def test_quality_on_a_small_generated_grid(tmp_path: Path) -> None:
    """Central goal of a 5 x 5 grid (seed 0). Measured: mean AE over the pairs 0.3-1.2 m away
    2.9 deg (warping) and 3.3 deg (min-warping), RR 1.0 for both; thresholds sit a little above
    the errors and below the return ratio, so a regression shows."""
    config = {
        "output": str(tmp_path / "run"),
        "databases": {"room": {"world": SPEC.model_dump(mode="json")}},
        "conditions": ["room-room"],
        "goals": [[2, 2]],
        "methods": [{"method": "warping"}, {"method": "min-warping"}],
        "jobs": 2,
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.stderr
    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    near = pairs[(pairs["distance_m"] >= 0.3 - 1e-9) & (pairs["distance_m"] <= 1.2 + 1e-9)]
    mean_ae = near.groupby("method")["ae_deg"].mean()
    goals = pd.read_csv(tmp_path / "run" / "tables" / "goals.csv").set_index("method")
    assert (near["ae_deg"].notna()).all()
    assert (mean_ae < 8).all(), mean_ae
    assert (goals["rr"] > 0.9).all(), goals
    assert np.isfinite(goals["catchment"]).all()
