"""Which current positions a goal's job gets: ground truth from the grid's own coordinates."""

from __future__ import annotations

import math

import pytest

from homebench.config import RunConfig
from homebench.evaluation.plan import select_currents
from homebench.geometry import Grid

GRID = Grid((10, 17), 0.3, (1.65, 1.8))


def _config(currents: object) -> RunConfig:
    return RunConfig.model_validate(
        {
            "output": "unused",
            "databases": {"original": "synth-original"},
            "conditions": ["original-original"],
            "goals": [[0, 0]],
            "currents": currents,
            "methods": [{"method": "warping"}],
        }
    )


@pytest.mark.parametrize("goal", [(0, 0), (4, 8), (9, 16), (5, 3)])
@pytest.mark.parametrize(
    "currents, low, high",
    [("all", 0.0, math.inf), ({"min_distance": 0.3, "max_distance": 0.9}, 0.3, 0.9)],
)
def test_currents_are_the_positions_in_the_distance_range_but_the_goal(
    goal: tuple[int, int], currents: object, low: float, high: float
) -> None:
    """Distances in whole grid steps: k steps along one axis are exactly k * 0.3 m, so the
    range's ends (0.3 and 0.9 m) are kept despite 3 * 0.3 != 0.9 in floating point."""
    expected = [
        (i, j)
        for i in range(10)
        for j in range(17)
        if (i, j) != goal
        and low - 1e-9 <= 0.3 * math.hypot(i - goal[0], j - goal[1]) <= high + 1e-9
    ]
    found = select_currents(_config(currents), GRID, goal)
    assert found == expected
    if currents != "all":
        assert (goal[0], goal[1] + 3) in found or goal[1] + 3 > 16  # 0.9 m: the far end
        assert len(found) < 10 * 17 - 1
