"""The scenes of the methods' validation tests (tests/test_validation_<method>.py): the kinds of
scene each method's paper tested it on, built analytically so that the truth is exact.

- **The equal-distance arena**: tests/synthetic_panorama.py's round arena (wall radius 3 m) with
  the goal at its centre (:data:`CENTRE`): every wall point is 3 m from the goal, so the
  equal-distance assumption of 1-D warping (Franz et al. 1998) and of its successors holds
  exactly; a place ``d`` metres away has ``rho = d / 3``. :func:`ring` lays places round it.
- **A wall textured in azimuth and height** (:func:`rich_texture`, set by :func:`use_wall`):
  the arena's own texture is mostly a function of azimuth alone; its only change with height
  is a stripe pattern of period 120 deg in azimuth, so a method that compares vertical edges
  (min-warping's edge filter) sees a 3-fold symmetric wall and cannot tell psi from psi +-
  120 deg. The 2-D warping methods are validated on this wall.
- **Equal-distance horizon signals** (:func:`ring_signal`, :func:`equal_distance_signals`): 1-D
  signals of a ring of landmarks round the goal, ray-traced, so that a search on warping's
  grid must find the parameters exactly, and at the ring's centre the image change of a small
  step is MFDID's matched filter to first order.
- **Neighbour views** (:func:`neighbours`, :func:`neighbour_error`): the views a few cm from a
  place that DID fits its gradient over, as the engine hands them from a grid database.
- **The landmark arena** (:func:`landmark_arena`): the landmark-homing papers' scene, black
  cylinders on a bright wall, as a generated world (style ``arena``: walls lit 2:1 unevenly by
  four lamps), photographed through the camera at every position of a 5 x 5 grid, beside its
  ground-truth control (``render: landmarks``: the same world's objects black on white, no
  light, no camera). :func:`pair_angles` and :func:`pair_truths` give every ordered pair's
  estimate and true home direction, :func:`landmark_scores` a method's scores on both.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import pytest
import synthetic_panorama
from numpy.typing import NDArray
from synthetic_panorama import home_errors, render

from homebench.data.synth.spec import GridSpec, RawImageSpec, UnfoldedImageSpec, WorldSpec
from homebench.data.synth.world import build_world, render_position
from homebench.geometry import Pose, angular_error, home_direction, world_to_robot_xy
from homebench.methods.base import HomingMethod, View

FloatArray = NDArray[np.float64]
Texture = Callable[[FloatArray, FloatArray], FloatArray]

#: The goal of the equal-distance arena: its centre (heading 0.3 rad, any would do).
CENTRE = Pose(0.0, 0.0, 0.3)

_rng = np.random.default_rng(7)
_CYCLES = _rng.integers(1, 12, 24)  # per turn of azimuth
_PER_METRE = _rng.uniform(0.5, 4.0, 24)  # cycles per metre of height
_PHASES = _rng.uniform(0.0, 2.0 * np.pi, (2, 24))
_AMPLITUDES = _rng.uniform(5.0, 12.5, 24)


def rich_texture(wall_angle: FloatArray, z: FloatArray) -> FloatArray:
    """Grey level (about 128 +- 60) of wall points at world angle ``wall_angle`` and height
    ``z`` (m): products of sinusoids in angle and height at incommensurate frequencies."""
    a, h = np.asarray(wall_angle)[..., None], np.asarray(z)[..., None]
    waves = np.sin(_CYCLES * a + _PHASES[0]) * np.sin(2.0 * np.pi * _PER_METRE * h + _PHASES[1])
    return 128.0 + np.sum(_AMPLITUDES * waves, axis=-1)


def use_wall(monkeypatch: pytest.MonkeyPatch, texture: Texture) -> None:
    """Render the arena with ``texture`` on its wall (for the calling test only)."""
    monkeypatch.setattr(synthetic_panorama, "wall_texture", texture)


def ring(distances: Sequence[float], n_directions: int, centre: Pose = CENTRE) -> list[Pose]:
    """Places ``distances`` metres from ``centre`` in ``n_directions`` directions (offset by 0.2
    rad from the axes, so that no direction falls on a search grid's step), at its heading."""
    return [
        Pose(
            centre.x + d * math.cos(2.0 * math.pi * k / n_directions + 0.2),
            centre.y + d * math.sin(2.0 * math.pi * k / n_directions + 0.2),
            centre.heading,
        )
        for d in distances
        for k in range(n_directions)
    ]


def arena_errors(
    method: HomingMethod, goal: Pose, places: Sequence[Pose], turns_deg: Sequence[float] = (0.0,)
) -> tuple[FloatArray, FloatArray]:
    """Home-direction and rotation errors (degrees, shape (len(places) * len(turns_deg),)) of
    ``method`` at every place, its view also turned on the spot by each of ``turns_deg`` (whole
    columns of the arena's panorama); no estimate counts as 180 deg, no rotation as NaN."""
    angles, rotations = [], []
    for place in places:
        for turn in turns_deg:
            angle, rotation, _ = home_errors(method, goal, place, math.radians(turn))
            angles.append(math.pi if angle is None else angle)
            rotations.append(math.nan if rotation is None else rotation)
    return np.degrees(angles), np.degrees(rotations)


def neighbours(method: HomingMethod, place: Pose, step: float) -> list[tuple[FloatArray, Any]]:
    """The four views ``step`` metres from ``place`` along world x and y, as DID's ``home``
    takes them: (offset in the robot frame (2,) metres, features)."""
    found = []
    for dx, dy in ((step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)):
        pose = Pose(place.x + dx, place.y + dy, place.heading)
        offset = world_to_robot_xy(np.array([dx, dy]), place.heading)
        found.append((offset, method.describe(render(pose))))
    return found


def neighbour_error(method: HomingMethod, goal: Pose, place: Pose, step: float) -> float:
    """Home-direction error (radians) of a method that takes the views of :func:`neighbours`
    (DID) at ``place``; no direction fails the test."""
    features = method.describe(render(place))
    estimate = method.home(features, method.describe(render(goal)), neighbours(method, place, step))
    assert estimate.angle is not None
    return float(angular_error(estimate.angle, home_direction(place.xy, goal.xy, place.heading)))


def ahc(errors_deg: FloatArray) -> float:
    """Average homeward component (seed 001, eq. 12): cos of the mean angular error."""
    return math.cos(math.radians(float(np.mean(errors_deg))))


def ring_texture(theta: FloatArray) -> FloatArray:
    """Grey level of the landmark ring of :func:`equal_distance_signals` at angle ``theta``."""
    return 100.0 + 30.0 * np.cos(2.0 * theta + 0.4) + 20.0 * np.sin(3.0 * theta) + np.cos(theta)


def ring_signal(x: float, y: float, heading: float, n: int) -> FloatArray:
    """Horizon signal (n,) in canonical columns seen from (x, y) (metres, inside the ring) with
    ``heading``: landmarks on the unit circle round the origin (:func:`ring_texture`),
    ray-traced (ray-circle intersection), independent of any homing model."""
    world = 2.0 * np.pi * np.arange(n) / n + heading
    along = x * np.cos(world) + y * np.sin(world)
    t = -along + np.sqrt(along**2 - (x**2 + y**2) + 1.0)
    return ring_texture(np.arctan2(y + t * np.sin(world), x + t * np.cos(world)))


def equal_distance_signals(
    rho: float, alpha: float, psi: float, n: int
) -> tuple[FloatArray, FloatArray, tuple[float, float]]:
    """Current and goal signals (n,) of :func:`ring_signal`: goal at the ring's centre, heading
    0; current at ``rho * (cos alpha, sin alpha)``, heading ``psi``. Returns (current, goal,
    current position)."""
    cx, cy = rho * math.cos(alpha), rho * math.sin(alpha)
    return ring_signal(cx, cy, psi, n), ring_signal(0.0, 0.0, 0.0, n), (cx, cy)


@dataclass(frozen=True)
class LandmarkArena:
    """A landmark arena's views at every grid position (n of them): ``photo`` through the
    camera and ``control`` its ground-truth landmarks, taken at ``poses``; ``centres`` (m, 2)
    of its cylinders, metres."""

    poses: list[Pose]
    photo: list[View]
    control: list[View]
    centres: FloatArray


@lru_cache(maxsize=3)
def landmark_arena(seed: int = 0) -> LandmarkArena:
    """The arena of world ``seed`` (style ``arena``, variant ``original``): a 5 x 5 grid 0.3 m
    apart, unfolded images 180 columns wide (2 deg per pixel), small raw images."""
    spec = WorldSpec(
        style="arena",
        seed=seed,
        grid=GridSpec(shape=(5, 5), spacing=0.3),
        raw=RawImageSpec(width=200, height=150, inner_radius=8, outer_radius=70),
        unfolded=UnfoldedImageSpec(width=180),
    )
    control = WorldSpec.model_validate({**spec.model_dump(), "render": "landmarks"})
    geometry, indices = spec.unfolded.geometry(), list(spec.to_grid().indices())
    cylinders = build_world(spec).scene.objects
    return LandmarkArena(
        [spec.pose(i, j) for i, j in indices],
        [View(render_position(spec, i, j)["unfolded"], geometry) for i, j in indices],
        [View(render_position(control, i, j)["unfolded"], geometry) for i, j in indices],
        np.array([c.centre for c in cylinders]),
    )


def pair_angles(method: HomingMethod, views: list[View]) -> FloatArray:
    """Home directions (radians; NaN: no estimate) of ``method`` for every ordered pair of
    ``views`` (goal k, current l != k; goals outermost), shape (n * (n - 1),)."""
    features = [method.describe(view) for view in views]
    angles = []
    for k, goal in enumerate(features):
        for current in features[:k] + features[k + 1 :]:
            angle = method.home(current, goal).angle
            angles.append(math.nan if angle is None else angle)
    return np.array(angles)


def pair_truths(poses: list[Pose]) -> FloatArray:
    """True home directions (radians, current robot frame) of the pairs of :func:`pair_angles`."""
    return np.array(
        [
            home_direction(current.xy, goal.xy, current.heading)
            for k, goal in enumerate(poses)
            for current in poses[:k] + poses[k + 1 :]
        ]
    )


def pair_errors(angles: FloatArray, truths: FloatArray) -> FloatArray:
    """Angular differences (degrees, same shape) of two sets of directions; NaN (no estimate)
    counts as 180 deg."""
    error = np.asarray(angular_error(np.nan_to_num(angles, nan=0.0), truths), dtype=np.float64)
    return np.degrees(np.where(np.isnan(angles) | np.isnan(truths), math.pi, error))


def landmark_scores(
    method: HomingMethod, control: HomingMethod, seeds: Sequence[int] = (0, 1, 2)
) -> dict[str, float]:
    """``method`` on the photographs of the landmark arenas of ``seeds``, pooled over their pairs:
    AHC, the share of pairs off by more than 45 deg, the mean difference (deg) of its estimates
    from ``control``'s on the ground-truth control, and that control's AHC."""
    arenas: list[LandmarkArena] = [landmark_arena(seed) for seed in seeds]
    photo = [pair_angles(method, arena.photo) for arena in arenas]
    truth = [pair_angles(control, arena.control) for arena in arenas]
    directions = [pair_truths(arena.poses) for arena in arenas]
    errors = np.concatenate([pair_errors(a, d) for a, d in zip(photo, directions, strict=True)])
    ideal = np.concatenate([pair_errors(a, d) for a, d in zip(truth, directions, strict=True)])
    deviation = np.concatenate([pair_errors(a, t) for a, t in zip(photo, truth, strict=True)])
    return {
        "ahc": ahc(errors),
        "gross": float(np.mean(errors > 45.0)),
        "deviation": float(np.mean(deviation)),
        "control_ahc": ahc(ideal),
    }
