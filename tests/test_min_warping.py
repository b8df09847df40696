"""Möller's min-warping: search against brute force, the compiled kernels against the numpy
reference, their buffers (reused, per thread, whatever they held), double and fine search, sign
convention, rotation, degenerate inputs.

Tolerance of the home direction on the arena world: 15 deg, as for 1-D warping (alpha and psi
in 3.75 deg steps, scales quantised to 9 planes); errors measured on these pairs stay below
about 8 deg.
"""

from __future__ import annotations

import math
import multiprocessing
import threading
import tracemalloc
from functools import lru_cache

import numpy as np
import pytest
import synthetic_panorama
from synthetic_panorama import home_errors, render, rolled

from homebench.errors import ConfigError
from homebench.geometry import Pose, angular_error, home_direction
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.min_warping.method import (
    MinWarping,
    column_distances,
    magnification_matrix,
    quantize,
)
from homebench.methods.min_warping.search import (
    CompiledSearch,
    NumpySearch,
    kernels,
    rotation_costs,
    search_template,
    workspace,
)

TOLERANCE = math.radians(15.0)
STEP = 2.0 * math.pi / 96  # one alpha / psi step of the default method
COLUMN = 2.0 * math.pi / 288  # one band column of the default method (the fine search's step)
GOAL = Pose(0.2, -0.3, 0.4)
DISTANCES = ["ssd", "sad", "zssd", "zsad", "nssd", "nsad", "znssd", "znsad"]
#: Plain SSD on grey levels: the arena tests' measure (its texture suits no other, see above).
SSD = {"distance": "ssd", "edge_filter": False}

_rng = np.random.default_rng(7)
_M, _F = _rng.integers(1, 12, 24), _rng.uniform(0.5, 4.0, 24)  # cycles per turn, per metre
_PHASE = _rng.uniform(0.0, 2.0 * np.pi, (2, 24))
_AMP = _rng.uniform(10.0, 25.0, 24)


def _rich_texture(wall_angle: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Grey level of a wall textured in both directions: products of sinusoids in angle and
    height at incommensurate frequencies."""
    a, h = np.asarray(wall_angle)[..., None], np.asarray(z)[..., None]
    waves = _AMP * np.sin(_M * a + _PHASE[0]) * np.sin(2.0 * np.pi * _F * h + _PHASE[1])
    return 128.0 + np.sum(waves, axis=-1)


@pytest.fixture
def rich_wall(monkeypatch: pytest.MonkeyPatch) -> None:
    """Render the arena with :func:`_rich_texture` on its wall."""
    monkeypatch.setattr(synthetic_panorama, "wall_texture", _rich_texture)


@lru_cache(maxsize=4)
def _admissible(n: int, n_scales: int, max_scale: float) -> list[set[tuple[int, int]]]:
    """Per goal offset x: the (plane, current offset) pairs some rho >= 0 reaches (brute force)."""
    h = (n_scales - 1) // 2
    out = []
    for x_col in range(n):
        x = 2.0 * math.pi * x_col / n
        pairs = set()
        for rho in np.linspace(0.0, 1.0 + max_scale, 30001):
            landmark = np.array([math.cos(x) - rho, math.sin(x)])  # seen from C, r = 1
            distance = float(np.hypot(*landmark))
            if distance < 1e-6:
                continue
            plane = round(h * math.log(1.0 / distance) / math.log(max_scale))
            if abs(plane) <= h:
                y = math.atan2(landmark[1], landmark[0])
                pairs.add((plane + h, round(y * n / (2.0 * math.pi)) % n))
        out.append(pairs)
    return out


def _brute_force(distances: np.ndarray, step: int) -> np.ndarray:
    """Cost of every (alpha, psi) step (n // step, n // step) from the brute-force pairs."""
    n_scales, n = distances.shape[:2]
    admissible = _admissible(n, n_scales, 2.0)
    steps = range(0, n, step)
    return np.array(
        [
            [
                sum(
                    int(min(distances[k, (x + a) % n, (y + a - p) % n] for k, y in admissible[x]))
                    for x in range(n)
                )
                for p in steps
            ]
            for a in steps
        ]
    )


@pytest.mark.parametrize("engine", ["numba", "numpy"])
@pytest.mark.parametrize("step", [1, 2])
def test_search_equals_the_brute_force_minimum(engine, step):
    n, n_scales = 16, 5
    method = MinWarping(n_columns=n // step, columns_per_step=step, n_scales=n_scales)
    stack = np.random.default_rng(1).integers(0, 256, (n_scales, n, n)).astype(np.uint8)
    swapped = np.ascontiguousarray(stack[::-1].transpose(0, 2, 1))
    np.testing.assert_array_equal(method.coarse(stack, engine), _brute_force(stack, step))
    np.testing.assert_array_equal(method.coarse(stack, engine, True), _brute_force(swapped, step))


def test_every_goal_column_may_stay_put_on_the_unit_scale_plane():
    template = search_template(288, 9, 2.0)
    for x in range(288):
        entries = slice(template.x_start[x], template.x_start[x + 1])
        pairs = list(zip(template.plane[entries], template.y[entries], strict=True))
        assert (4, x) in pairs
        assert len(pairs) == len(set(pairs))


# The default size (96 steps x 3 columns, 9 planes) takes 20 s in the numpy reference: slow.
@pytest.mark.parametrize(
    ("n_columns", "step", "n_scales"),
    [(12, 1, 3), (8, 3, 5), pytest.param(96, 3, 9, marks=pytest.mark.slow)],
)
def test_compiled_search_returns_the_numpy_reference_costs(n_columns, step, n_scales):
    method = MinWarping(n_columns=n_columns, columns_per_step=step, n_scales=n_scales)
    n = n_columns * step
    stack = np.random.default_rng(n).integers(0, 256, (n_scales, n, n)).astype(np.uint8)
    compiled, numpy = method.searcher(stack, "numba"), method.searcher(stack, "numpy")
    for swap in (False, True):
        np.testing.assert_array_equal(compiled.coarse(swap), numpy.coarse(swap))
        alphas, psis = np.array([0, 5, n - 1, -2]), np.array([0, n - 2, 7, 3])
        np.testing.assert_array_equal(compiled.at(alphas, psis, swap), numpy.at(alphas, psis, swap))
    fast, reference = method.search(stack, "numba"), method.search(stack, "numpy")
    assert fast[:3] == reference[:3]
    np.testing.assert_array_equal(fast[3], reference[3])


@pytest.mark.parametrize(
    ("dx", "dy", "heading", "distance"),
    # The default distance in the default selection, the other with the slow tests (20 s each).
    [(-1.2, -0.5, -2.0, "nsad"), pytest.param(0.0, 0.6, 0.4, "ssd", marks=pytest.mark.slow)],
)
def test_compiled_path_gives_the_numpy_reference_estimate(dx, dy, heading, distance):
    method = MinWarping(distance=distance)
    current = method.describe(render(Pose(GOAL.x + dx, GOAL.y + dy, heading)))
    goal = method.describe(render(GOAL))
    fast = method.quantized_stack(current, goal, "numba")
    reference = method.quantized_stack(current, goal, "numpy")
    assert np.max(np.abs(fast.astype(np.int64) - reference)) <= 1  # float32 vs float64 sums
    assert method.search(fast, "numba")[:3] == method.search(fast, "numpy")[:3]
    a, b = method.home(current, goal), method.home(current, goal, engine="numpy")
    assert (a.angle, a.rotation, a.diagnostics) == (b.angle, b.rotation, b.diagnostics)


def _features(*poses: Pose) -> list[np.ndarray]:
    method = MinWarping()
    return [method.describe(render(pose)) for pose in poses]


def _estimate(current: np.ndarray, goal: np.ndarray) -> tuple:
    estimate = MinWarping().home(current, goal)
    return estimate.angle, estimate.rotation, estimate.score


def test_read_only_features_give_the_same_estimate():
    """Feature files are read into read-only arrays: the compiled kernels take them as they
    are (each kernel has its one signature, read-only inputs)."""
    current, goal = _features(Pose(-0.4, 0.5, 1.0), GOAL)
    expected = _estimate(current, goal)
    for array in (current, goal):
        array.flags.writeable = False
    assert _estimate(current, goal) == expected
    compiled = kernels()
    for name, signature in compiled.SIGNATURES.items():
        assert getattr(compiled, name).signatures == [signature.args]


def test_a_home_after_the_first_allocates_nothing_large():
    current, goal, other = _features(Pose(-0.4, 0.5, 1.0), GOAL, Pose(0.9, -0.2, 2.0))
    method = MinWarping()
    method.home(current, goal)
    tracemalloc.start()
    try:
        method.home(other, goal)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1_000_000  # the float stack, the stack and the tables (13 MB) are kept


def test_results_do_not_depend_on_what_the_buffers_held():
    current, goal = _features(Pose(-0.4, 0.5, 1.0), GOAL)
    expected = _estimate(current, goal)
    for array, _ in workspace()._arrays.values():
        array[...] = 255 if array.dtype == np.uint8 else np.nan
    assert _estimate(current, goal) == expected


def test_a_search_rebuilds_a_table_another_search_overwrote():
    method = MinWarping(n_columns=16, columns_per_step=2, n_scales=5)
    rng = np.random.default_rng(4)
    stacks = [rng.integers(0, 256, (5, 32, 32)).astype(np.uint8) for _ in range(2)]
    first, second = (CompiledSearch(s, method.template, 2) for s in stacks)
    for searcher, stack in [(first, stacks[0]), (second, stacks[1]), (first, stacks[0])]:
        reference = NumpySearch(stack, method.template, 2)
        for swap in (False, True):
            np.testing.assert_array_equal(searcher.coarse(swap), reference.coarse(swap))


def test_threads_search_with_their_own_buffers():
    poses = [Pose(-0.4, 0.5, 1.0), Pose(0.9, -0.2, 2.0), Pose(0.3, 0.8, -1.0), Pose(-1.0, 0.1, 0)]
    *currents, goal = _features(*poses, GOAL)
    expected = [_estimate(current, goal) for current in currents]
    results: dict[int, list[tuple]] = {}

    def work(k: int) -> None:
        results[k] = [_estimate(current, goal) for current in currents * 3]

    threads = [threading.Thread(target=work, args=(k,)) for k in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert all(result == expected * 3 for result in results.values())


def test_a_forked_process_searches_as_its_parent():
    current, goal = _features(Pose(-0.4, 0.5, 1.0), GOAL)
    expected = _estimate(current, goal)  # the parent's buffers exist before the fork
    with multiprocessing.get_context("fork").Pool(1) as pool:
        assert pool.apply(_estimate, (current, goal)) == expected


def test_rotation_costs_are_the_wrapped_diagonal_sums():
    """Each psi's cost is the sum over goal columns i of plane[i, (i - psi) % n], for coarse
    steps and fine offsets (any psi in band columns, negative and past n too)."""
    plane = np.random.default_rng(3).integers(0, 256, (12, 12)).astype(np.uint8)
    psis = np.array([0, 3, 6, 9, 1, 2, 11, -1, 13])
    i = np.arange(12)
    expected = [int(plane[i, (i - psi) % 12].astype(np.int64).sum()) for psi in psis]
    np.testing.assert_array_equal(rotation_costs(plane, psis), expected)


def test_quantize_scales_the_largest_distance_to_255():
    stack = np.array([[[0.0, 1.0], [2.0, 4.0]]], dtype=np.float32)
    np.testing.assert_array_equal(quantize(stack), [[[0, 64], [128, 255]]])


def test_swapping_the_views_swaps_the_parameters_exactly():
    """Double search: the summed cost is the same function of the movement either way round, so
    the views swapped give alpha' = alpha - psi + pi and psi' = -psi (fine search included)."""
    method = MinWarping()
    a = method.describe(render(Pose(GOAL.x + 0.7, GOAL.y - 0.5, 1.3)))
    b = method.describe(render(GOAL))
    forward, backward = method.home(a, b).diagnostics, method.home(b, a).diagnostics
    alpha, psi = forward["alpha"], forward["psi"]
    assert angular_error(backward["psi"], -psi) < 1e-9
    assert angular_error(backward["alpha"], alpha - psi + math.pi) < 1e-9


def test_fine_search_refines_within_one_step_and_never_costs_more():
    coarse_only, fine = MinWarping(fine_search=False), MinWarping()
    current = fine.describe(render(Pose(GOAL.x - 0.9, GOAL.y + 0.4, -0.7)))
    stack = fine.quantized_stack(current, fine.describe(render(GOAL)), "numba")
    cost_c, alpha_c, psi_c, _ = coarse_only.search(stack)
    cost_f, alpha_f, psi_f, _ = fine.search(stack)
    assert alpha_c % 3 == psi_c % 3 == 0
    assert cost_f <= cost_c
    assert abs(alpha_f - alpha_c) <= 2 and abs(psi_f - psi_c) <= 2


def test_magnification_matrix():
    elevations = np.radians(np.linspace(14.0, -14.0, 15))
    np.testing.assert_allclose(magnification_matrix(elevations, 1.0), np.eye(15), atol=1e-12)
    column = np.tan(elevations)  # an object of linear height profile
    magnified = magnification_matrix(elevations, 2.0) @ column
    np.testing.assert_allclose(magnified, column / 2.0, atol=2e-3)


@pytest.mark.parametrize("distance", DISTANCES)
def test_distance_planes_below_one_mirror_those_above(distance):
    method = MinWarping(distance=distance)
    a = method.describe(render(GOAL))
    b = method.describe(render(Pose(1.0, 0.5, 2.0)))
    forward, backward = method.distance_stack(a, b), method.distance_stack(b, a)
    np.testing.assert_allclose(forward, backward[::-1].transpose(0, 2, 1), rtol=1e-5, atol=1e-4)


@pytest.mark.parametrize(
    ("dx", "dy"), [(0.6, 0.0), (-0.6, 0.0), (0.0, 0.6), (0.0, -0.6), (1.0, 0.7), (-1.2, -0.5)]
)
@pytest.mark.parametrize("heading", [0.4, -2.0])
def test_home_direction_along_x_and_y(dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    angle_error, rotation_error, _ = home_errors(MinWarping(**SSD), GOAL, current)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.usefixtures("rich_wall")
@pytest.mark.parametrize("edge_filter", [True, False])
@pytest.mark.parametrize("distance", DISTANCES)
@pytest.mark.parametrize(("dx", "dy", "heading"), [(0.0, 0.6, 0.4), (-1.2, -0.5, -2.0)])
def test_every_distance_measure_homes(distance, edge_filter, dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    method = MinWarping(distance=distance, edge_filter=edge_filter)
    angle_error, rotation_error, _ = home_errors(method, GOAL, current)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.parametrize("rotation_deg", [30.0, -97.5, 180.0])
def test_a_current_view_turned_on_the_spot_keeps_the_right_direction(rotation_deg):
    current = Pose(GOAL.x - 0.5, GOAL.y + 0.7, 1.0)
    rotation = math.radians(rotation_deg)
    angle_error, rotation_error, _ = home_errors(MinWarping(**SSD), GOAL, current, rotation)
    assert angle_error is not None and angle_error < TOLERANCE
    assert rotation_error is not None and rotation_error <= STEP


@pytest.mark.parametrize(("k", "fine_search"), [(3, False), (39, False), (1, True), (143, True)])
def test_psi_recovers_a_roll_without_a_direction(k, fine_search):
    method = MinWarping(fine_search=fine_search)
    goal_view = render(GOAL)
    # canonical columns are ccw: rolling the image right by k columns = turning cw by k columns
    estimate = method.home(method.describe(rolled(goal_view, k)), method.describe(goal_view))
    assert angular_error(estimate.rotation, -k * COLUMN) < 1e-9
    assert estimate.angle is None  # a pure rotation: no (alpha, psi) explains it better


@pytest.mark.parametrize("distance", DISTANCES)
def test_identical_columns_are_at_distance_zero(distance):
    columns = np.random.default_rng(2).normal(0.0, 30.0, (15, 6))
    d = column_distances(columns, columns, distance)
    np.testing.assert_allclose(np.diag(d), 0.0, atol=1e-9)
    assert np.all(d >= 0.0) and np.all(d[~np.eye(6, dtype=bool)] > 1e-3)


@pytest.mark.parametrize("distance", DISTANCES)
def test_invariances_of_the_column_distances(distance):
    """z...: an offset added to one view's columns changes nothing; n...: nor does a gain on
    both views (each normalised measure is a ratio of sums of like powers); plain: both do."""
    rng = np.random.default_rng(3)
    goal, current = rng.normal(100.0, 30.0, (15, 8)), rng.normal(100.0, 30.0, (15, 8))
    d = column_distances(goal, current, distance)
    offset = column_distances(goal, current + 37.0, distance)
    gain = column_distances(2.5 * goal, 2.5 * current, distance)
    assert np.allclose(offset, d, rtol=1e-12, atol=1e-9) == distance.startswith("z")
    assert np.allclose(gain, d, rtol=1e-12) == ("n" in distance)
    if distance.endswith("nsad"):
        assert np.all(d <= 1.0)
    if distance.endswith("nssd"):
        assert np.all(d <= 2.0)


def test_the_edge_filter_removes_an_offset_of_the_whole_view():
    view = render(GOAL)
    darker = View((view.image // 2).astype(np.uint8), view.geometry)
    lifted = View(darker.image + np.uint8(60), view.geometry)  # exact: values <= 187
    for edge_filter in (True, False):
        method = MinWarping(distance="ssd", edge_filter=edge_filter)
        same = np.allclose(method.describe(lifted), method.describe(darker), atol=1e-3)
        assert same == edge_filter


@pytest.mark.usefixtures("rich_wall")
@pytest.mark.parametrize(("dx", "dy", "heading"), [(0.6, -0.4, 1.0), (-0.5, 0.7, -2.0)])
def test_the_default_homes_when_the_goal_view_is_twice_as_bright(dx, dy, heading):
    current = Pose(GOAL.x + dx, GOAL.y + dy, heading)
    method = MinWarping()
    dim = render(current)
    dim = View((dim.image // 2).astype(np.uint8), dim.geometry)
    goal = render(GOAL)
    bright = View((goal.image // 2).astype(np.uint8) * np.uint8(2), goal.geometry)
    estimate = method.home(method.describe(dim), method.describe(bright))
    truth = home_direction(current.xy, GOAL.xy, heading)
    assert estimate.angle is not None and angular_error(estimate.angle, truth) < TOLERANCE


def test_a_textureless_view_gives_no_estimate_and_no_nan():
    method = MinWarping()
    textured = method.describe(render(GOAL))
    flat = np.full(textured.shape, 90.0, dtype=np.float32)
    for current, goal in [(flat, textured), (textured, flat), (flat, flat)]:
        estimate = method.home(current, goal)
        assert estimate.angle is None and estimate.rotation is None


@pytest.mark.parametrize(("edge_filter", "rows"), [(True, 15), (False, 16)])
def test_describe_gives_the_magnified_band_stack(edge_filter, rows):
    features = MinWarping(edge_filter=edge_filter).describe(render(GOAL))
    assert features.shape == (5, rows, 288) and features.dtype == np.float32
    assert np.all(np.isfinite(features))


def test_registered_with_moller_defaults():
    method = registry.create("min-warping")
    assert isinstance(method, MinWarping)
    np.testing.assert_allclose(method.scales[[0, 4, 8]], [0.5, 1.0, 2.0])
    assert (method.distance, method.edge_filter) == ("nsad", True)
    assert (method.n_columns, method.columns_per_step, method.band_columns) == (96, 3, 288)
    assert method.double_search and method.fine_search


@pytest.mark.parametrize(
    "params",
    [
        {"n_scales": 8},
        {"max_scale": 1.0},
        {"band_bottom_deg": 2.0},
        {"n_columns": 2},
        {"n_rows": 1},
        {"distance": "ncc"},
        {"columns_per_step": 0},
        {"n_columns": 95},
    ],
)
def test_bad_parameters_are_config_errors(params):
    with pytest.raises(ConfigError):
        MinWarping(**params)
