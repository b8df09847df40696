"""Validation of Fourier-based warping (Stürzl and Mallot 2006) on its paper's scene: 1-D
warping's, every landmark at one distance from the goal.

1. **Equal-distance signals** (exact): landmarks on a circle round the goal, ray-traced for
   displacements and turns on the search grid; the signal has three harmonics, so its 10
   coefficients hold it whole: rho, alpha and psi are found exactly, the home direction to
   1e-9 rad.
2. **The equal-distance arena** (rendered panoramas, tests/validation_scenes.py): the goal at
   the centre of the round arena, 24 places 0.3, 0.9 and 1.5 m away (rho 0.1-0.5) in 8
   directions, each view as it is and turned by -37.5 deg. Measured: mean AE 5.3 deg (AHC
   0.996), at most 23.2 deg (0.3 m away: the 10 coefficients keep wavelengths of 40 deg and
   more, whose shift over 0.3 m is small against the 5 deg steps); the turn to within half a
   psi step (2.5 deg). Held to a mean of 8, a maximum of 30 and the half step.
"""

from __future__ import annotations

import numpy as np
import pytest
from validation_scenes import CENTRE, arena_errors, equal_distance_signals, ring

from homebench.geometry import angular_error, home_direction
from homebench.methods.warping.fourier import FourierWarping

N = 360  # samples of the equal-distance signals


@pytest.mark.parametrize(
    ("r", "a", "p"), [(6, 0, 0), (10, 9, 20), (4, 30, 60), (15, 50, 5), (19, 71, 36)]
)
def test_search_recovers_the_parameters_of_an_equal_distance_world(r, a, p):
    method = FourierWarping()
    rho, alpha, psi = method.rho[r], 2 * np.pi * a / 72, 2 * np.pi * p / 72
    current, goal, xy = equal_distance_signals(rho, alpha, psi, N)
    c = np.fft.rfft(np.stack([current, goal]), axis=-1)[:, : method.n_coefficients] / N
    estimate = method.home(c[0], c[1])
    assert estimate.diagnostics["rho"] == pytest.approx(rho)
    assert estimate.diagnostics["alpha"] == pytest.approx(alpha)
    assert angular_error(estimate.rotation, psi) < 1e-9
    assert angular_error(estimate.angle, home_direction(xy, (0.0, 0.0), psi)) < 1e-9


def test_equal_distance_arena():
    places = ring((0.3, 0.9, 1.5), 8)
    angle, rotation = arena_errors(FourierWarping(), CENTRE, places, (0.0, -37.5))
    assert angle.mean() < 8.0 and angle.max() < 30.0
    assert np.all(rotation <= 2.5 + 1e-6)
