"""Franz's 1-D warping: the warp model, the sign convention, rotation, degenerate inputs.

Tolerance of the home direction on the arena world: 15 deg. Alpha and psi are searched in 5 deg
steps (up to 2.5 deg of quantisation each, both enter beta = alpha - psi + pi), and the arena
violates the equal-distance assumption (wall 2-4 m from the goal), which bends the estimate by a
few more degrees; errors measured on these pairs stay below about 10 deg.
The paper's own scene, the method's validation: tests/test_validation_warping.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_panorama import home_errors, render, rolled
from validation_scenes import ring_texture
from warping_reference import direct_costs

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.warping.method import Warping, best_hypothesis, normalize_signal, warp_tables

TOLERANCE = math.radians(15.0)
STEP = math.radians(5.0)  # one psi step: the rotation is found to within one step
GOAL = Pose(0.2, -0.3, 0.4)


def test_warp_tables_at_rho_zero_reproduce_the_goal_for_every_alpha():
    goal = np.random.default_rng(3).normal(size=72)
    low, frac = warp_tables(72, (0.0, 0.5), 8)
    warped = (1.0 - frac) * goal[low] + frac * goal[(low + 1) % 72]
    np.testing.assert_allclose(warped[:8], np.tile(goal, (8, 1)), atol=1e-9)
    assert np.max(np.abs(warped[8:] - goal)) > 0.5  # rho = 0.5 does warp


@pytest.mark.parametrize(
    ("dx", "dy"), [(0.6, 0.0), (-0.6, 0.0), (0.0, 0.6), (0.0, -0.6), (1.0, 0.7), (-1.2, -0.5)]
)
@pytest.mark.parametrize("heading", [0.4, -2.0])
def test_home_direction_along_x_and_y(dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    angle_error, rotation_error, _ = home_errors(Warping(), GOAL, current)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.parametrize("rotation_deg", [35.0, -100.0, 180.0])
def test_a_current_view_turned_on_the_spot_keeps_the_right_direction(rotation_deg):
    current = Pose(GOAL.x - 0.5, GOAL.y + 0.7, 1.0)
    rotation = math.radians(rotation_deg)
    angle_error, rotation_error, _ = home_errors(Warping(), GOAL, current, rotation)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.parametrize("k", [1, 7, 40, 71])
def test_psi_recovers_a_roll_by_whole_steps_and_rho_zero_gives_no_direction(k):
    method = Warping()
    goal_view = render(GOAL)
    # canonical columns are ccw: rolling the image right by 4 columns = turning cw by 5 deg
    current = method.describe(rolled(goal_view, 4 * k))
    estimate = method.home(current, method.describe(goal_view))
    assert angular_error(estimate.rotation, -k * math.radians(5.0)) < 1e-9
    assert estimate.diagnostics["rho"] == 0.0
    assert estimate.angle is None


def test_identical_views_give_no_direction_and_no_rotation():
    method = Warping()
    signal = method.describe(render(GOAL))
    estimate = method.home(signal, signal)
    assert estimate.angle is None and estimate.rotation == 0.0
    assert estimate.score == pytest.approx(0.0, abs=1e-6)


def test_a_textureless_view_gives_no_estimate_and_no_nan():
    method = Warping()
    flat = np.full(72, 90.0)
    textured = method.describe(render(GOAL))
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None
        assert estimate.n_landmarks == 72


def test_describe_gives_the_canonical_horizon_signal():
    signal = Warping(n_columns=360, n_psi=72).describe(render(GOAL))
    assert signal.shape == (360,)
    assert np.all(np.isfinite(signal))


def test_registered_with_table_1_defaults():
    method = registry.create("warping")
    assert isinstance(method, Warping)
    assert (method.n_rho, method.rho_max, method.n_alpha, method.n_psi) == (20, 0.95, 72, 72)
    assert method.rho[1] == pytest.approx(0.05)


@pytest.mark.parametrize(
    "params", [{"n_columns": 100}, {"rho_max": 1.0}, {"n_rho": 1}, {"band_half_width_deg": 0.0}]
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        Warping(**params)


@pytest.mark.parametrize("mode", ["equalize", "zscore"])
def test_normalized_signals_ignore_gain_and_offset(mode):
    signal = ring_texture(2.0 * np.pi * np.arange(72) / 72)
    same = normalize_signal(signal, mode)
    np.testing.assert_allclose(normalize_signal(3.0 * signal + 40.0, mode), same, atol=1e-12)
    if mode == "equalize":  # any increasing grey-level mapping, even a non-linear one
        np.testing.assert_array_equal(normalize_signal(np.exp(signal), mode), same)
    assert np.all(
        normalize_signal(np.full(72, 90.0), mode) == normalize_signal(np.full(72, 7.0), mode)
    )  # a flat signal stays flat


@pytest.mark.parametrize("mode", ["none", "equalize", "zscore"])
def test_normalize_makes_the_search_blind_to_a_brighter_goal(mode):
    """A goal image twice as bright (exact in 8 bits below 128) changes no normalised cost."""
    dim = render(GOAL)
    dim = View((dim.image // 2).astype(np.uint8), dim.geometry)
    bright = View(dim.image * 2, dim.geometry)  # exact: every value is even and <= 254
    method = Warping(normalize=mode)
    current = method.describe(render(Pose(GOAL.x + 0.5, GOAL.y - 0.3, 1.0)))
    costs = method.costs(current, method.describe(bright))
    unchanged = np.allclose(costs, method.costs(current, method.describe(dim)), atol=1e-9)
    assert unchanged == (mode != "none")  # the paper's grey levels feel the gain


def test_dot_distance_is_minus_the_scalar_product():
    rng = np.random.default_rng(5)
    current, goal = rng.uniform(0, 255, 72), rng.uniform(0, 255, 72)
    ssd = Warping().costs(current, goal)
    dot = Warping(distance="dot").costs(current, goal)
    # ssd = ||c||^2 + ||w||^2 - 2 c.w and dot = -c.w: ssd - 2 dot is the two signals' energy,
    # which depends on (rho, alpha) through the warped signal but never on psi
    energy = ssd - 2.0 * dot
    np.testing.assert_allclose(energy, energy[..., :1] * np.ones(72), rtol=1e-9)
    assert not np.allclose(ssd, dot)


def test_unknown_choices_are_config_errors():
    with pytest.raises(ConfigError, match="normalize: expected one of none, equalize, zscore"):
        Warping(normalize="histogram")
    with pytest.raises(ConfigError, match="distance"):
        Warping(distance="sad")


def _signals(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Two smooth random grey-level signals (current, goal) of n columns."""
    rng = np.random.default_rng(seed)
    spectrum = rng.normal(size=(2, n // 2 + 1)) + 1j * rng.normal(size=(2, n // 2 + 1))
    signals = np.fft.irfft(spectrum * np.exp(-np.arange(n // 2 + 1) / 4.0), n=n)
    return tuple(128.0 + 60.0 * signals / signals.std(axis=1, keepdims=True))


# small grids for the direct search: s = t, t a multiple of s (unit s), s a multiple of t, dot
SMALL_GRIDS = [
    {"n_columns": 24, "n_alpha": 24, "n_psi": 24},
    {"n_columns": 24, "n_alpha": 24, "n_psi": 12},
    {"n_columns": 48, "n_alpha": 12, "n_psi": 24},
    {"n_columns": 24, "n_alpha": 8, "n_psi": 24, "distance": "dot"},
]


@pytest.mark.parametrize("params", SMALL_GRIDS)
def test_costs_are_the_direct_search_and_home_finds_their_minimum(params):
    method = Warping(n_rho=5, rho_max=0.8, **params)
    for seed in range(3):
        current, goal = _signals(seed, method.n_columns)
        costs = method.costs(current, goal)
        np.testing.assert_allclose(costs, direct_costs(method, current, goal), rtol=1e-12)
        estimate = method.home(current, goal)
        assert estimate == best_hypothesis(costs, method.rho, method.n_columns)
        assert estimate.score == costs.min()


@pytest.mark.parametrize("params", [{}, {"distance": "dot"}, {"n_psi": 36}])
def test_home_is_the_first_minimum_of_the_costs_on_the_table_1_grid(params):
    method = Warping(**params)
    arena = [method.describe(render(Pose(GOAL.x + dx, GOAL.y, 1.0))) for dx in (0.0, 0.4, -0.9)]
    pairs = [_signals(seed, 72) for seed in range(4)] + [(arena[1], arena[0]), (arena[2], arena[0])]
    for current, goal in pairs:
        expected = best_hypothesis(method.costs(current, goal), method.rho, method.n_columns)
        assert method.home(current, goal) == expected


def test_exact_ties_go_to_the_lowest_alpha_and_psi():
    """rho = 0 warps alike for every alpha, and a signal of period n/2 matches two psi alike:
    the float32 screen must not decide such ties, the first hypothesis wins."""
    method = Warping()
    half = _signals(7, 36)[0]
    goal = np.tile(half, 2)
    current = np.roll(goal, -5)  # current[k] = goal[k + 5]: psi of 5 columns, and 41
    costs = method.costs(current, goal)
    assert costs[0, 0, 5] == costs[0, 40, 5] == costs[0, 0, 41] == 0.0
    estimate = method.home(current, goal)
    assert (estimate.diagnostics["rho"], estimate.diagnostics["alpha"]) == (0.0, 0.0)
    assert estimate.rotation == pytest.approx(5 * STEP, abs=1e-12)  # psi 5, not 41
    assert estimate.score == 0.0 and estimate.angle is None


def test_a_goal_kept_from_an_earlier_pair_gives_the_same_estimates():
    kept, fresh = Warping(), Warping()
    goals = [_signals(seed, 72)[1] for seed in range(6)]  # more goals than the method keeps
    current = _signals(9, 72)[0]
    for goal in goals + goals[::-1]:
        assert kept.home(current, goal) == Warping().home(current, goal)
    assert kept == fresh  # the kept goals are no parameter


def test_alpha_must_be_whole_columns():
    with pytest.raises(ConfigError, match="n_alpha"):
        Warping(n_alpha=50)


@pytest.mark.parametrize("scale", [1e30, 1e-11])
def test_signals_beyond_float32_are_searched_exactly(scale):
    """Grey levels whose squares float32 cannot hold skip the screen: the same first minimum."""
    method = Warping()
    current, goal = (signal * scale for signal in _signals(3, 72))
    expected = best_hypothesis(method.costs(current, goal), method.rho, method.n_columns)
    assert method.home(current, goal) == expected
    assert expected.angle is not None
