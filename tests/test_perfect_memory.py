"""Perfect memory and the familiarity protocol on constructed views, where the answer is exact.

Sign convention (DESIGN.md, azimuth ccw, column p at azimuth 2*pi*p/n): a robot that turns ccw
by k columns sees what it saw at column p at column p - k, so its view is the stored view
rolled by -k (:func:`homebench.imaging.rotation.rotate_view`). The way the stored view faced
then lies k columns clockwise in the robot frame: direction -k columns, heading change +k.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from homebench.errors import ConfigError
from homebench.geometry import PanoramaGeometry
from homebench.imaging.rotation import rotate_view
from homebench.methods import registry
from homebench.methods.base import View
from homebench.methods.familiarity.perfect_memory import PerfectMemory
from homebench.methods.familiarity.route_memory import learns_route, most_familiar, rotations

N = 36
COLUMN = 2.0 * math.pi / N


def _views(count: int, seed: int = 0, shape: tuple[int, int] = (5, N)) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [rng.uniform(0.0, 1.0, shape) for _ in range(count)]


def _same_angle(a: float | None, b: float) -> bool:
    """Whether angles ``a`` and ``b`` (rad) agree to 1e-12 (a half turn is -pi or pi)."""
    return a is not None and abs(math.remainder(a - b, 2.0 * math.pi)) < 1e-12


def test_rotations_are_the_rolls_of_the_image() -> None:
    image = _views(1, shape=(3, 7))[0]
    rolled = rotations(image)
    assert rolled.shape == (7, 21)
    for s in range(7):
        assert np.array_equal(rolled[s], np.roll(image, s, axis=-1).ravel())


@pytest.mark.parametrize("shift", [0, 1, 9, 18, 35])
def test_most_familiar_turns_the_shift_into_direction_and_rotation(shift: int) -> None:
    profile = np.ones(N)
    profile[shift] = 0.25
    estimate = most_familiar(profile, view=3)
    assert _same_angle(estimate.angle, -shift * COLUMN)
    assert _same_angle(estimate.rotation, shift * COLUMN)
    assert estimate.score == 0.25 and estimate.diagnostics == {"shift": shift, "view": 3}


@pytest.mark.parametrize("k", [1, 5, 13, -7, 18])
def test_a_stored_view_turned_by_k_columns_points_minus_k_columns_at_the_right_view(k) -> None:
    """The robot at the third stored place, turned ccw by k columns: direction exactly -k
    columns, heading change +k columns, the third view recognised, unfamiliarity 0."""
    method = PerfectMemory()
    views = _views(5)
    memory = method.learn(views)
    assert memory.shape == (5, 5, N)
    estimate = method.follow(memory, np.roll(views[2], -k, axis=-1))
    assert _same_angle(estimate.angle, -k * COLUMN)
    assert _same_angle(estimate.rotation, k * COLUMN)
    assert estimate.diagnostics["view"] == 2
    assert estimate.score == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(
    ("difference", "measure"),
    [
        ("mad", lambda a, b: np.mean(np.abs(a - b))),
        ("rms", lambda a, b: np.sqrt(np.mean((a - b) ** 2))),
    ],
)
def test_the_ridf_is_the_smallest_difference_over_the_stored_views(difference, measure) -> None:
    """Per column shift, the smallest difference to any stored view: mean absolute (BoB's
    AbsDiff: cv::absdiff then cv::mean) or root mean square, written out."""
    method = PerfectMemory(difference=difference)
    views = _views(3, seed=1)
    current = _views(1, seed=2)[0]
    profile = method.unfamiliarity(method.learn(views), current)
    expected = [
        min(measure(np.roll(current, s, axis=-1), view) for view in views) for s in range(N)
    ]
    assert np.allclose(profile, expected, rtol=0, atol=1e-12)


def test_the_default_difference_is_the_mean_absolute_one_of_brains_on_board() -> None:
    assert PerfectMemory().difference == "mad"
    with pytest.raises(ConfigError, match="difference"):
        PerfectMemory(difference="ssd")  # type: ignore[arg-type]


@pytest.mark.parametrize("k", [0, 7, -12])
def test_mad_and_rms_recognise_different_views(k: int) -> None:
    """Stored view A is the current place's view with every pixel 0.2 off; stored view B is
    the same view with 20 of its 180 pixels 0.9 off and the others exact. By hand: the mean
    absolute difference is 0.2 for A and 20 * 0.9 / 180 = 0.1 for B, so mad recognises B; the
    root mean square is 0.2 for A and sqrt(20 * 0.81 / 180) = 0.3 for B, so rms recognises A.
    Every other rotation differs more from both (a random texture), so both find the turn."""
    place = np.random.default_rng(5).uniform(0.0, 1.0, (5, N))
    near_a = np.where(place < 0.8, place + 0.2, place - 0.2)
    near_b = place.copy()
    extreme = np.flatnonzero((place < 0.1) | (place > 0.9))[:20]
    assert extreme.size == 20
    flat = near_b.reshape(-1)
    flat[extreme] = np.where(flat[extreme] < 0.1, flat[extreme] + 0.9, flat[extreme] - 0.9)
    assert np.allclose(np.abs(near_a - place), 0.2) and np.count_nonzero(near_b - place) == 20
    current = np.roll(place, -k, axis=-1)  # the robot turned ccw by k columns
    found = {}
    for difference in ("mad", "rms"):
        method = PerfectMemory(difference=difference)
        estimate = method.follow(method.learn([near_a, near_b]), current)
        assert _same_angle(estimate.angle, -k * COLUMN)
        found[difference] = (estimate.diagnostics["view"], estimate.score)
    assert found["mad"][0] == 1 and found["mad"][1] == pytest.approx(0.1, abs=1e-12)
    assert found["rms"][0] == 0 and found["rms"][1] == pytest.approx(0.2, abs=1e-12)


def test_describe_keeps_the_sign_through_a_rendered_size_panorama() -> None:
    """A 360-column panorama turned ccw by 40 columns (40 deg) through rotate_view, described
    at 90 columns (4 deg): the memory points -40 deg."""
    geometry = PanoramaGeometry(360, 30, math.radians(40.0), math.radians(-40.0))
    rng = np.random.default_rng(4)
    smooth = np.cumsum(rng.normal(0.0, 8.0, (30, 360)), axis=1)
    smooth -= np.linspace(0.0, 1.0, 360) * smooth[:, -1:]  # periodic in azimuth
    image = np.clip(128 + smooth, 0, 255).astype(np.uint8)
    stored = View(image, geometry)
    current = rotate_view(stored, math.radians(40.0))
    method = PerfectMemory()
    assert method.describe(stored).shape == (17, 90)
    estimate = method.follow(method.learn([method.describe(stored)]), method.describe(current))
    assert math.degrees(estimate.angle) == pytest.approx(-40.0, abs=1e-9)


def test_on_a_pair_it_is_a_compass_without_direction() -> None:
    method = PerfectMemory()
    goal = _views(1)[0]
    estimate = method.home(np.roll(goal, -4, axis=-1), goal)
    assert estimate.angle is None and estimate.rotation == pytest.approx(4 * COLUMN)
    assert method.home(goal, np.full_like(goal, 0.5)).rotation is None  # a flat goal: none


def test_a_flat_view_gives_no_estimate_and_the_registry_lists_both() -> None:
    method = PerfectMemory()
    estimate = method.follow(method.learn(_views(2)), np.full((5, N), 0.3))
    assert estimate.angle is None and estimate.rotation is None
    for name in ("perfect-memory", "infomax"):
        cls = registry.get(name)
        assert learns_route(cls) and not cls.gives_direction and cls.image_kind == "unfolded"
    assert not learns_route(registry.get("warping"))
    with pytest.raises(ConfigError, match="image_size must be positive"):
        PerfectMemory(image_size=(0, 17))
