"""2D-warping on the scale-plane stack (warping-2d's ``scheme="scale-planes"``): the template
against the geometry of a landmark at unit distance, the compiled search against the numpy
reference (the same integers, partial sums that cannot overflow), a planted hypothesis found
exactly, and the method on rendered views (sign convention, rotation, degenerate inputs).

Rendered views: the arena with tests/validation_scenes.py's rich wall (the arena's own wall
repeats every 120 deg once edge-filtered, which makes psi ambiguous for min-warping's default
column distance, as tests/test_min_warping.py notes). Tolerance 15 deg per pair, as for the image
scheme (the arena violates the equal-distance assumption); the rotation to one alpha / psi step
(3.75 deg), as min-warping's: the true turn lies between the band's columns and the coarse
search picks a step before the fine search.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from conftest import run_config
from synthetic_panorama import GEOMETRY, home_errors, render, rolled
from validation_scenes import rich_texture, use_wall

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error
from homebench.methods.min_warping.search import NumpySearch
from homebench.methods.params import paper_statement, parameter_docs
from homebench.methods.warping.method import rho_grid
from homebench.methods.warping_2d.method import Warping2D
from homebench.methods.warping_2d.planes import (
    CompiledPlaneSearch,
    ScalePlaneWarping2D,
    plane_template,
    reference_costs,
)

RHO = rho_grid(0.95, 20)
GOAL = Pose(0.2, -0.3, 0.4)
TOLERANCE = math.radians(15.0)
COLUMN = 2.0 * math.pi / 288  # one band column: the fine search's step
STEP = 3 * COLUMN  # one alpha / psi step of the coarse search


@pytest.fixture(autouse=True)
def _rich_wall(monkeypatch: pytest.MonkeyPatch) -> None:
    use_wall(monkeypatch, rich_texture)


def _planes(**params: object) -> Warping2D:
    return Warping2D(scheme="scale-planes", **params)


def test_the_template_is_where_a_landmark_at_unit_distance_is_seen():
    n, n_scales, max_scale = 288, 9, 2.0
    template = plane_template(n, RHO, n_scales, max_scale)
    assert template.plane.shape == template.y.shape == (20, n)
    np.testing.assert_array_equal(template.plane[0], 4)  # rho = 0: the unit plane, in place
    np.testing.assert_array_equal(template.y[0], np.arange(n))
    for r in (3, 11, 19):
        for x in (0, 40, 100, 144, 200, 287):
            theta = 2.0 * math.pi * x / n
            # the robot moved rho along alpha (x = 0); the landmark is at unit distance
            ahead, aside = math.cos(theta) - RHO[r], math.sin(theta)
            seen = math.atan2(aside, ahead) % (2.0 * math.pi)
            assert template.y[r, x] == round(seen / (2.0 * math.pi / n)) % n
            magnification = 1.0 / math.hypot(ahead, aside)  # closer: larger
            plane = 4 + round(4 * math.log(magnification) / math.log(max_scale))
            assert template.plane[r, x] == min(max(plane, 0), 8)


@pytest.mark.parametrize(
    ("n", "step", "n_scales"), [(24, 1, 5), (36, 3, 9), (40, 2, 5), (48, 4, 7)]
)
def test_the_compiled_search_gives_the_reference_costs(n, step, n_scales):
    """Steps of 1, 2, 3 and 4 columns: the goal columns of one step go three at a time, the
    rest one at a time."""
    rng = np.random.default_rng(n)
    stack = rng.integers(0, 256, (n_scales, n, n), dtype=np.uint8)
    template = plane_template(n, RHO, n_scales, 2.0)
    compiled = CompiledPlaneSearch(stack, template, step)
    numpy = NumpySearch(stack, template, step, reference_costs)
    alphas, psis = rng.integers(-n, 2 * n, 12), rng.integers(-n, 2 * n, 12)
    for swap in (False, True):
        np.testing.assert_array_equal(compiled.coarse(swap), numpy.coarse(swap))
        np.testing.assert_array_equal(compiled.at(alphas, psis, swap), numpy.at(alphas, psis, swap))


def test_partial_sums_of_288_columns_do_not_overflow():
    """288 goal columns of 255 sum to 73,440, beyond 16 bits: the search folds its 16-bit
    partial sums before they could overflow."""
    n, step = 288, 3
    full = np.full((9, n, n), 255, dtype=np.uint8)
    template = plane_template(n, RHO[:3], 9, 2.0)
    np.testing.assert_array_equal(CompiledPlaneSearch(full, template, step).coarse(False), n * 255)
    stack = np.random.default_rng(1).integers(0, 256, (9, n, n), dtype=np.uint8)
    grid = step * np.arange(n // step)
    reference = reference_costs(stack, template, grid[::7], grid)
    np.testing.assert_array_equal(
        CompiledPlaneSearch(stack, template, step).coarse(False)[::7], reference
    )


@pytest.mark.parametrize("double_search", [False, True])
@pytest.mark.parametrize(("r", "alpha", "psi"), [(5, 12, 30), (17, 81, 3), (9, 0, 57)])
def test_a_planted_hypothesis_is_found_exactly(double_search, r, alpha, psi):
    """Zeros where the template of (rho[r], alpha, psi) reads (alpha, psi in steps), every
    other entry 100-255: the search finds those parameters with cost 0 (the swapped reading
    adds its own cost with double search) and beats the best pure rotation."""
    method = ScalePlaneWarping2D(rho=RHO, double_search=double_search, fine_search=False)
    n, step = method.band_columns, method.columns_per_step
    template = method.plane_template
    stack = np.random.default_rng(r).integers(100, 256, (9, n, n), dtype=np.uint8)
    x = np.arange(n)
    a, p = step * alpha, step * psi
    stack[template.plane[r], (x + a) % n, (template.y[r] + a - p) % n] = 0
    best, found_alpha, found_psi, _ = method.search(stack)
    assert (found_alpha, found_psi) == (a, p)
    if not double_search:
        assert best == 0


@pytest.mark.parametrize(
    ("dx", "dy"), [(0.6, 0.0), (-0.6, 0.0), (0.0, 0.6), (0.0, -0.6), (1.0, 0.7)]
)
@pytest.mark.parametrize("heading", [0.4, -2.0])
def test_home_direction_along_x_and_y(dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    angle_error, rotation_error, _ = home_errors(_planes(), GOAL, current)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


def test_the_numpy_reference_gives_the_same_estimate():
    method = _planes(n_columns=48)
    goal = method.describe(render(GOAL))
    current = method.describe(render(Pose(GOAL.x - 0.5, GOAL.y + 0.4, 1.3)))
    assert method.home(current, goal, engine="numpy") == method.home(current, goal)


@pytest.mark.parametrize("columns", [45, -81, 144])
def test_a_current_view_turned_on_the_spot_keeps_the_world_direction(columns):
    method = _planes()
    current, goal = render(Pose(GOAL.x - 0.5, GOAL.y + 0.7, 1.0)), method.describe(render(GOAL))
    straight = method.home(method.describe(current), goal)
    turned = method.home(method.describe(rolled(current, columns)), goal)
    # rolling right by one column turns the robot cw by one; by whole steps, the coarse
    # search's grid turns with the view
    rotation = -columns * COLUMN
    assert angular_error(turned.rotation, straight.rotation + rotation) < 1e-9
    assert angular_error(turned.angle + rotation, straight.angle) < 1e-9


def test_a_pure_rotation_is_found_to_the_column_and_gives_no_direction():
    method = _planes()
    goal_view = render(GOAL)
    estimate = method.home(method.describe(rolled(goal_view, 50)), method.describe(goal_view))
    assert angular_error(estimate.rotation, -50 * COLUMN) < 1e-9
    assert estimate.angle is None


def test_a_textureless_view_gives_no_estimate():
    method = _planes()
    textured = method.describe(render(GOAL))
    flat = np.full_like(textured, 0.0)
    for current, goal in [(flat, textured), (textured, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None


def test_features_are_min_warpings_magnified_bands():
    assert _planes().describe(render(GOAL)).shape == (5, 15, 288)  # sigma 1 .. 2, edges, columns
    assert Warping2D().describe(render(GOAL)).shape == (30, 96)  # the image scheme's band


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"n_scales": 5}, "n_scales: only with scheme 'scale-planes'"),
        ({"distance": "ssd", "fine_search": False}, "distance, fine_search: only with"),
        ({"scheme": "scale-planes", "n_columns": 95}, "warping-2d: double_search needs an even"),
        ({"scheme": "scale-planes", "n_scales": 4}, "warping-2d: n_scales must be odd"),
        ({"scheme": "pixels"}, "scheme"),
    ],
)
def test_bad_parameters_are_config_errors(params, message):
    with pytest.raises(ConfigError, match=message):
        Warping2D(**params)


def test_listed_as_a_departure_with_its_scheme_only_parameters():
    docs = {doc.name: doc for doc in parameter_docs(Warping2D)}
    assert docs["scheme"].status == "departure" and docs["scheme"].default == "'image'"
    for name in ("columns_per_step", "n_scales", "distance", "double_search", "fine_search"):
        assert docs[name].meaning.startswith("Scheme 'scale-planes' only.")
    assert "scheme = 'scale-planes'" in paper_statement(Warping2D, {"scheme": "scale-planes"})
    assert GEOMETRY.width == 288  # the views above: one image column per band column


def test_at_rho_one_the_landmark_ahead_is_on_the_outermost_plane_a_quarter_turn_on():
    """rho = 1 puts the robot on the landmark straight ahead (x = 0): its magnification is
    unbounded and its direction undefined; Möller's template takes a quarter turn."""
    template = plane_template(96, (0.0, 1.0), 9, 2.0)
    assert template.plane[1, 0] == 8 and template.y[1, 0] == 24
    assert template.plane[1, 48] == 0  # behind: twice as far, half the size (1 / max_scale)
    method = Warping2D(scheme="scale-planes")
    assert method.rho == rho_grid(1.0, 20)
    assert Warping2D(scheme="scale-planes", rho_max=0.5).rho[-1] == 0.5
    with pytest.raises(ConfigError, match="rho_max"):
        Warping2D(scheme="scale-planes", rho_max=1.01)
    with pytest.raises(ConfigError, match="rho_max"):
        Warping2D(rho_max=1.0)


def test_a_run_sweeps_both_schemes_in_job_workers(tmp_path):
    """Both schemes in one run's job workers (their features differ in shape, so they must be
    stored apart), every pair estimated by each."""
    config = {
        "name": "schemes",
        "output": str(tmp_path / "run"),
        "databases": {"room": {"world": {"grid": {"shape": [3, 3]}}}},
        "conditions": ["room-room"],
        "goals": [[1, 1]],
        "methods": [{"method": "warping-2d", "grid": {"scheme": ["image", "scale-planes"]}}],
    }
    result = run_config(tmp_path, config, "--jobs", "2")
    assert result.exit_code == 0, result.output
    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    assert len(pairs) == 2 * 8 and pairs["method"].nunique() == 2
    assert pairs["ae_deg"].notna().all()
