"""Infomax on constructed inputs: the initial weights, one learning step by hand, the scan, a
one-view memory as a compass, and its failure modes. The references' facts tested: the authors'
MATLAB code (infomax_train.m, infomax_init2.m, in Brains on Board's bob_robotics under
examples/infomax/matlab) trains with mu = 0.001 scaled by 1 / N and starts from standard normal
weights with each input's weights normalised over the units; Brains on Board's C++ InfoMax
(include/navigation/infomax.h) scales by 1 / (N H) with a rate of 0.97."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.errors import ConfigError
from homebench.methods.familiarity.infomax import Infomax

N_COLUMNS = 36
COLUMN = 2.0 * math.pi / N_COLUMNS


def test_the_defaults_are_the_authors_matlab_code() -> None:
    method = Infomax()
    assert (method.learning_rate, method.learning_rate_scaling) == (0.001, "per-input")
    assert (method.init, method.epochs, method.hidden_units) == ("normal", 1, None)
    assert method.standardize is False


def test_start_weights_are_normal_and_each_input_has_mean_0_and_sd_1_over_the_units() -> None:
    """infomax_init2.m and BoB's generateInitialWeights: standard normal draws, then each
    input's weights (a column of the H x N matrix) to mean 0 and SD 1 (divided by H)."""
    weights = Infomax(seed=3).start_weights(200)
    assert weights.shape == (200, 200)  # as many units as inputs by default
    assert np.allclose(weights.mean(axis=0), 0.0) and np.allclose(weights.std(axis=0), 1.0)
    assert not np.allclose(weights.mean(axis=1), 0.0, atol=0.05)  # not per unit
    # normal, not uniform: a normal puts 4.55 % of its mass beyond 2 SD; a uniform none
    assert 0.035 < np.mean(np.abs(weights) > 2.0) < 0.055
    assert np.array_equal(weights, Infomax(seed=3).start_weights(200))
    assert not np.array_equal(weights, Infomax(seed=4).start_weights(200))
    few = Infomax(hidden_units=5).start_weights(40)
    assert few.shape == (5, 40)
    assert np.allclose(few.mean(axis=0), 0.0) and np.allclose(few.std(axis=0), 1.0)


def test_uniform_start_weights_have_each_unit_at_mean_0_and_sd_1() -> None:
    """homebench's earlier reading, an option: uniform draws, each unit (row) normalised, so
    each unit's weights sum to 0 and hardly any lies beyond 2 SD (a uniform reaches sqrt(3))."""
    weights = Infomax(seed=3, init="uniform").start_weights(200)
    assert np.allclose(weights.mean(axis=1), 0.0) and np.allclose(weights.std(axis=1), 1.0)
    assert np.mean(np.abs(weights) > 2.0) < 0.001
    assert Infomax(hidden_units=1, init="uniform").start_weights(4).shape == (1, 4)


def test_the_step_is_the_rate_over_n_or_over_n_times_h() -> None:
    """The MATLAB code's lrate / N, and BoB's m_LearningRate / (numInputs * numHidden): at
    90 x 17 views and H = N, BoB's 0.97 gives 0.97 / 1530**2, 0.63 times the MATLAB step."""
    n = 17 * 90
    matlab = Infomax().step_size(n, n)
    bob = Infomax(learning_rate=0.97, learning_rate_scaling="per-input-and-unit").step_size(n, n)
    assert matlab == pytest.approx(0.001 / 1530, rel=1e-12)
    assert bob == pytest.approx(4.1437e-7, rel=1e-4)
    assert bob / matlab == pytest.approx(0.634, abs=0.001)
    assert Infomax(learning_rate=0.5).step_size(3, 2) == pytest.approx(0.5 / 3)


@pytest.mark.parametrize(
    ("scaling", "step"), [("per-input", 0.5 / 3), ("per-input-and-unit", 0.5 / 6)]
)
def test_one_view_changes_the_weights_by_the_infomax_rule_written_out(scaling, step) -> None:
    """Element by element: W_ij += step * (W_ij - (y_i + h_i) * sum_k h_k W_kj), with h = W x,
    y = tanh(h) and step = eta / N or eta / (N * H), for a (1, 3) view and two units."""
    method = Infomax(
        hidden_units=2, learning_rate=0.5, image_size=(3, 1), learning_rate_scaling=scaling
    )
    x = np.array([0.2, 0.9, 0.4])
    w = method.start_weights(3)
    h = [sum(w[i, j] * x[j] for j in range(3)) for i in range(2)]
    back = [sum(h[k] * w[k, j] for k in range(2)) for j in range(3)]  # (h^T W)_j
    expected = np.array(
        [
            [w[i, j] + step * (w[i, j] - (math.tanh(h[i]) + h[i]) * back[j]) for j in range(3)]
            for i in range(2)
        ]
    )
    assert np.allclose(method.learn([x.reshape(1, 3)]), expected, rtol=0, atol=1e-12)


def test_views_are_learnt_in_order_once_per_epoch() -> None:
    views = [np.random.default_rng(k).uniform(0.0, 1.0, (2, 6)) for k in range(3)]
    one, two = Infomax(hidden_units=4), Infomax(hidden_units=4, epochs=2)
    first = one.learn(views)
    assert not np.allclose(first, one.learn(views[::-1]))  # order matters
    assert not np.allclose(two.learn(views), first)


def test_the_scan_is_the_summed_absolute_activation_of_every_roll() -> None:
    rng = np.random.default_rng(1)
    method = Infomax(hidden_units=7)
    weights = rng.normal(size=(7, 3 * 8))
    current = rng.uniform(0.0, 1.0, (3, 8))
    expected = [np.abs(weights @ np.roll(current, s, axis=-1).ravel()).sum() for s in range(8)]
    assert np.allclose(method.unfamiliarity(weights, current), expected, atol=1e-12)


@pytest.mark.parametrize("k", [3, -11])
def test_a_one_view_memory_of_a_contrasted_view_finds_the_turn(k: int) -> None:
    """Trained on one view of grey levels spread over [0, 1] (defaults), the view itself is the
    most familiar of its rotations, so the view turned ccw by k columns points -k columns."""
    view = np.random.default_rng(3).uniform(0.0, 1.0, (6, N_COLUMNS))
    method = Infomax()
    memory = method.learn([view])
    before = np.abs(method.start_weights(view.size) @ view.ravel()).sum()
    profile = method.unfamiliarity(memory, view)
    assert int(np.argmin(profile)) == 0 and profile[0] < before  # learning made it familiar
    estimate = method.follow(memory, np.roll(view, -k, axis=-1))
    assert estimate.angle == pytest.approx(-k * COLUMN, abs=1e-12)


def test_standardize_gives_the_network_zero_mean_unit_sd_views() -> None:
    view = np.random.default_rng(2).uniform(0.4, 0.5, (3, 10))
    seen = Infomax(standardize=True).standardized(view)
    assert seen.mean() == pytest.approx(0.0, abs=1e-12) and seen.std() == pytest.approx(1.0)
    assert np.array_equal(Infomax().standardized(view), view)
    assert not Infomax(standardize=True).standardized(np.full((3, 10), 0.7)).any()


def test_blown_up_weights_and_bad_parameters_are_errors() -> None:
    view = np.random.default_rng(0).uniform(0.0, 1.0, (4, 12))
    with pytest.raises(ValueError, match="blew up with learning_rate 1000"):
        Infomax(learning_rate=1000.0, epochs=20).learn([view] * 5)
    for bad in (
        {"learning_rate": 0.0},
        {"epochs": 0},
        {"hidden_units": 0},
        {"hidden_units": 1},  # a normal start normalises each input over the units
        {"init": "xavier"},
        {"learning_rate_scaling": "per-unit"},
    ):
        with pytest.raises(ConfigError, match="infomax|init|learning_rate_scaling"):
            Infomax(**bad)
