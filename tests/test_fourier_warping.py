"""Stürzl and Mallot's Fourier-based warping: the warped coefficients, the search, degenerate
inputs.

Tolerance of the home direction on the arena world: 20 deg. The search steps are 1-D warping's
(5 deg for alpha and psi, up to 2.5 deg of quantisation each), the arena violates the
equal-distance assumption (as for 1-D warping, a few degrees), and the 10 coefficients keep only
the horizon's coarse structure (wavelengths of 40 deg and more), so the warp is fitted to a
low-pass image whose fine parallax is gone. Measured on these pairs: at most 10 deg; mean 8 deg
(at most 19 deg) over the 5 x 5 lattice.
The paper's own scene, the method's validation: tests/test_validation_fourier_warping.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import home_errors, render, rolled
from validation_scenes import ring_texture

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error
from homebench.methods import registry
from homebench.methods.warping.fourier import FourierWarping, full_spectrum, warp_matrices

TOLERANCE = math.radians(20.0)
STEP = math.radians(5.0)
GOAL = Pose(0.2, -0.3, 0.4)
N = 360


def _coefficients(signal: np.ndarray, k: int = 10) -> np.ndarray:
    return np.fft.rfft(signal)[:k] / signal.size


def test_warped_coefficients_are_those_of_the_warped_signal():
    """The Fourier-domain warp equals warping the signal (eq. 2 of 1-D warping, evaluated on
    the analytic texture) and transforming it: up to the aliasing of the 360 samples."""
    method = FourierWarping(n_rho=5, n_alpha=8)
    phi = 2.0 * np.pi * np.arange(N) / N
    alpha = 2.0 * np.pi * np.arange(8) / 8
    rho = np.asarray(method.rho)[:, None, None]
    theta = phi - np.arcsin(rho * np.sin(phi - alpha[:, None]))  # (rho, alpha, N)
    expected = np.fft.rfft(ring_texture(theta), axis=-1)[..., :10] / N
    warped = method.warped(_coefficients(ring_texture(phi)))
    np.testing.assert_allclose(warped, expected, atol=1e-9)


def test_rho_zero_is_the_identity():
    a = warp_matrices(4, (0.0,))[0]
    np.testing.assert_allclose(a, np.eye(4, 7, k=3), atol=1e-12)  # n = -3 .. 3, m = 0 .. 3


def test_full_spectrum_adds_the_conjugate_negative_frequencies():
    c = np.array([5.0, 1 + 2j, 3 - 1j])
    np.testing.assert_array_equal(full_spectrum(c), [3 + 1j, 1 - 2j, 5.0, 1 + 2j, 3 - 1j])


@pytest.mark.parametrize(
    ("dx", "dy"), [(0.6, 0.0), (-0.6, 0.0), (0.0, 0.6), (0.0, -0.6), (1.0, 0.7), (-1.2, -0.5)]
)
@pytest.mark.parametrize("heading", [0.4, -2.0])
def test_home_direction_along_x_and_y(dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    angle_error, rotation_error, _ = home_errors(FourierWarping(), GOAL, current)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.parametrize("rotation_deg", [35.0, -100.0, 180.0])
def test_a_current_view_turned_on_the_spot_keeps_the_world_direction(rotation_deg):
    """Turning by whole psi steps shifts psi and the home direction by exactly the turn."""
    method = FourierWarping()
    current, goal = render(Pose(GOAL.x - 0.5, GOAL.y + 0.7, 1.0)), method.describe(render(GOAL))
    straight = method.home(method.describe(current), goal)
    rotation = math.radians(rotation_deg)
    turned = method.home(method.describe(rolled(current, -round(rotation_deg / 1.25))), goal)
    assert angular_error(turned.rotation, straight.rotation + rotation) < 1e-9
    assert angular_error(turned.angle + rotation, straight.angle) < 1e-9


@pytest.mark.parametrize("k", [1, 7, 40, 71])
def test_a_pure_rotation_is_found_and_gives_no_direction(k):
    method = FourierWarping()
    goal_view = render(GOAL)
    current = method.describe(rolled(goal_view, 4 * k))
    estimate = method.home(current, method.describe(goal_view))
    assert angular_error(estimate.rotation, -k * STEP) < 1e-9
    assert estimate.diagnostics["rho"] == 0.0 and estimate.angle is None


def test_identical_views_give_no_direction_and_no_rotation():
    method = FourierWarping()
    c = method.describe(render(GOAL))
    estimate = method.home(c, c)
    assert estimate.angle is None and estimate.rotation == 0.0
    assert estimate.score == pytest.approx(0.0, abs=1e-9)


def test_a_textureless_view_gives_no_estimate():
    method = FourierWarping()
    flat = np.zeros(10, dtype=np.complex128)
    flat[0] = 90.0
    textured = method.describe(render(GOAL))
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None


def test_describe_gives_the_first_coefficients():
    c = FourierWarping().describe(render(GOAL))
    assert c.shape == (10,) and c.dtype == np.complex128
    assert c[0].imag == 0.0 and 0.0 < c[0].real < 255.0  # the mean grey level


def test_registered_with_the_defaults():
    method = registry.create("fourier-warping")
    assert isinstance(method, FourierWarping)
    assert (method.n_coefficients, method.n_rho, method.n_alpha, method.n_psi) == (10, 20, 72, 72)


@pytest.mark.parametrize(
    "params", [{"n_coefficients": 1}, {"n_coefficients": 200}, {"rho_max": 1.0}, {"n_psi": 0}]
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        FourierWarping(**params)


def test_arena_lattice_mean_error():
    """5 x 5 lattice, 0.3 m spacing, headings varied: mean error below 12 deg (measured 8 deg;
    the low-pass signal leaves single pairs up to 19 deg off)."""
    method = FourierWarping()
    errors = []
    for i in range(-2, 3):
        for j in range(-2, 3):
            if i or j:
                pose = Pose(GOAL.x + 0.3 * i, GOAL.y + 0.3 * j, 0.4 + 0.7 * i - 0.3 * j)
                error, _, _ = home_errors(method, GOAL, pose)
                errors.append(math.pi if error is None else error)
    assert np.mean(errors) < math.radians(12.0)
