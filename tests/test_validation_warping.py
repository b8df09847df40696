"""Validation of 1-D warping (Franz et al. 1998) on its paper's scene: every landmark at one
distance from the goal, the assumption its warping equations rest on.

1. **Equal-distance signals** (exact): landmarks on a circle round the goal, ray-traced for
   displacements and turns on Table 1's grid: the search finds rho, alpha and psi exactly and
   the home direction to 1e-9 rad.
2. **The equal-distance arena** (rendered panoramas, tests/validation_scenes.py): the goal at
   the centre of the round arena, 24 places 0.3, 0.9 and 1.5 m away (rho 0.1-0.5) in 8
   directions, each view as it is and turned by -37.5 deg (7.5 psi steps). Measured: mean AE
   2.5 deg (AHC 0.999), at most 13.2 deg (0.3 m away, where the parallax is small against the
   5 deg steps); the turn to within half a psi step (2.5 deg). Held to a mean of 4, a maximum
   of 20 and the half step.
"""

from __future__ import annotations

import numpy as np
import pytest
from validation_scenes import CENTRE, arena_errors, equal_distance_signals, ring

from homebench.geometry import angular_error, home_direction
from homebench.methods.warping.method import Warping


@pytest.mark.parametrize(
    ("r", "a", "p"), [(6, 0, 0), (10, 9, 20), (4, 30, 60), (15, 50, 5), (19, 71, 36)]
)
def test_search_recovers_the_parameters_of_an_equal_distance_world(r, a, p):
    method = Warping()
    rho, alpha, psi = method.rho[r], 2 * np.pi * a / 72, 2 * np.pi * p / 72
    current, goal, xy = equal_distance_signals(rho, alpha, psi, 72)
    estimate = method.home(current, goal)
    assert estimate.diagnostics["rho"] == pytest.approx(rho)
    assert estimate.diagnostics["alpha"] == pytest.approx(alpha)
    assert angular_error(estimate.rotation, psi) < 1e-9
    truth = home_direction(xy, (0.0, 0.0), psi)
    assert angular_error(estimate.angle, truth) < 1e-9


def test_equal_distance_arena():
    angle, rotation = arena_errors(Warping(), CENTRE, ring((0.3, 0.9, 1.5), 8), (0.0, -37.5))
    assert angle.mean() < 4.0 and angle.max() < 20.0
    assert np.all(rotation <= 2.5 + 1e-6)
