"""An analytic test world for panoramic homing tests: a textured circular arena.

The robot stands inside a cylindrical wall of radius ``ARENA_RADIUS`` (centred on the world
origin, from the floor z = 0 up to ``WALL_HEIGHT``). The wall carries a smooth grey texture that
is a known function of the wall point (its world angle around the arena centre and its height);
the floor and the ceiling are plain. :func:`render` casts one ray per pixel of an unfolded
panorama, so any pose can be rendered exactly, with any :class:`PanoramaGeometry`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import PanoramaGeometry, Pose, angular_error, home_direction
from homebench.methods.base import HomingEstimate, HomingMethod, View

ARENA_RADIUS = 3.0  # metres
WALL_HEIGHT = 2.0  # metres
CAMERA_HEIGHT = 0.8  # metres
FLOOR_GREY = 40.0
CEILING_GREY = 215.0

#: Unfolded geometry of the test panoramas: 288 columns, 1.25 degrees per row, +-30 degrees.
GEOMETRY = PanoramaGeometry(
    width=288, height=48, elevation_top=math.radians(30.0), elevation_bottom=math.radians(-30.0)
)

_rng = np.random.default_rng(20240611)
#: Wall texture: sum of sinusoids over the wall angle (frequencies 1..16 cycles per turn).
_FREQ = np.arange(1, 17)
_AMP = 40.0 / np.sqrt(_FREQ) * _rng.uniform(0.5, 1.0, _FREQ.size)
_PHASE = _rng.uniform(0.0, 2.0 * np.pi, _FREQ.size)


def wall_texture(wall_angle: NDArray[np.float64], z: NDArray[np.float64]) -> NDArray[np.float64]:
    """Grey level (0..255) of wall points at world angle ``wall_angle`` and height ``z`` (m)."""
    a = np.asarray(wall_angle)[..., None]
    horizontal = np.sum(_AMP * np.sin(_FREQ * a + _PHASE), axis=-1)
    stripes = 25.0 * np.sin(2.0 * np.pi * np.asarray(z) / 0.5) * np.cos(3.0 * wall_angle)
    return 128.0 + horizontal + stripes


def render_float(pose: Pose, geometry: PanoramaGeometry = GEOMETRY) -> NDArray[np.float64]:
    """Exact panorama (height, width) in grey levels seen from ``pose`` (inside the arena)."""
    azimuth, elevation = geometry.bearing_grid()
    return render_rays(pose.x, pose.y, pose.heading + azimuth[0], elevation[:, 0])


def render_rays(
    x: float,
    y: float,
    world_azimuth: NDArray[np.float64],
    elevation: NDArray[np.float64],
    texture: Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]
    | None = None,
) -> NDArray[np.float64]:
    """Grey levels (height, width) seen from (x, y) along each column's world direction
    ``world_azimuth`` (width,) (radians, ccw from +x) at each row's ``elevation`` (height,)
    (radians): an image laid out by any convention, without homebench's camera models. The
    wall carries ``texture`` (default :func:`wall_texture`)."""
    if math.hypot(x, y) >= ARENA_RADIUS:
        raise ValueError("the pose must lie inside the arena")
    ux, uy = np.cos(world_azimuth), np.sin(world_azimuth)
    along = x * ux + y * uy
    distance = -along + np.sqrt(along**2 - (x**2 + y**2) + ARENA_RADIUS**2)
    wall_angle = np.arctan2(y + distance * uy, x + distance * ux)
    z = CAMERA_HEIGHT + distance[None, :] * np.tan(elevation)[:, None]
    wall = (texture or wall_texture)(np.broadcast_to(wall_angle, z.shape), z)
    image = np.where(z > WALL_HEIGHT, CEILING_GREY, np.where(z < 0.0, FLOOR_GREY, wall))
    return np.clip(image, 0.0, 255.0)


def render(pose: Pose, geometry: PanoramaGeometry = GEOMETRY) -> View:
    """The uint8 :class:`View` seen from ``pose``."""
    return View(np.rint(render_float(pose, geometry)).astype(np.uint8), geometry)


def rolled(view: View, columns: int) -> View:
    """``view`` with its image rolled by ``columns`` (a turn on the spot by whole columns)."""
    return View(np.roll(view.image, columns, axis=1), view.geometry)


def home_errors(
    method: HomingMethod, goal: Pose, current: Pose, rotation: float = 0.0
) -> tuple[float | None, float | None, HomingEstimate]:
    """Angular errors (radians) of a method's home direction and rotation at ``current``.

    The current view is also turned on the spot by ``rotation`` (ccw, a whole number of
    columns) by rolling its image. Returns (home direction error or None, rotation error or
    None, the estimate).
    """
    view = render(current)
    shift = view.geometry.columns_for_rotation(rotation)
    if abs(shift - round(shift)) > 1e-9:
        raise ValueError("rotation must be a whole number of columns")
    estimate = method.home(
        method.describe(rolled(view, round(shift))), method.describe(render(goal))
    )
    heading = current.heading + rotation
    true_home = home_direction(current.xy, goal.xy, heading)
    true_rotation = heading - goal.heading
    angle_error = (
        None if estimate.angle is None else float(angular_error(estimate.angle, true_home))
    )
    rotation_error = (
        None
        if estimate.rotation is None
        else float(angular_error(estimate.rotation, true_rotation))
    )
    return angle_error, rotation_error, estimate
