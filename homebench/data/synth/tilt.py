"""A camera mount that is never quite vertical: the tilt of a capture's view axis.

A tilt turns the view sphere about the camera centre, which does not move, so the tilted
camera's panorama is the upright one resampled: the tilted camera's pixel at azimuth ``a`` and
elevation ``e`` (its own frame) looks along ``R d(a, e)`` in the upright robot frame (x ahead,
y to the left, z up; ``d(a, e) = (cos e cos a, cos e sin a, sin e)``), where ``R`` leans the
camera's axis (z) by ``angle`` towards the robot-frame azimuth ``direction`` (a rotation about
the horizontal axis perpendicular to that azimuth; no turn about the axis itself, the heading
being the pose's). Resampling is exact up to the interpolation of the upright panorama
(bilinear on the 4 x supersampled cast), provided the upright panorama reaches ``angle``
beyond the tilted one's elevations: :func:`level_geometry` adds that margin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.geometry import FloatArray, PanoramaGeometry

Float32 = NDArray[np.float32]
#: Rows beyond the margin that a tilt's angle needs (bilinear interpolation reads one more).
_SPARE_ROWS = 2
#: Columns added at each side of the upright panorama so that interpolation wraps in azimuth.
_WRAP_COLUMNS = 2


@dataclass(frozen=True)
class Tilt:
    """The camera axis leant by ``angle`` (radians) towards robot azimuth ``direction``."""

    angle: float
    direction: float

    @classmethod
    def draw(cls, max_deg: float, rng: np.random.Generator) -> Tilt:
        """A random tilt: the tilt vector (angle along direction) uniform over the disc of
        radius ``max_deg`` degrees (angle ``max * sqrt(u)``, direction uniform)."""
        u, v = rng.random(2)
        return cls(math.radians(max_deg) * math.sqrt(u), 2 * math.pi * v)

    def degrees(self) -> dict[str, float]:
        """The tilt as JSON: ``angle_deg`` and ``direction_deg``."""
        return {
            "angle_deg": math.degrees(self.angle),
            "direction_deg": math.degrees(self.direction),
        }

    def matrix(self) -> FloatArray:
        """``R``, shape (3, 3): camera-frame unit vectors to upright robot-frame ones."""
        kx, ky = -math.sin(self.direction), math.cos(self.direction)  # the horizontal axis
        c, s = math.cos(self.angle), math.sin(self.angle)
        k = np.array([kx, ky, 0.0])
        cross = np.array([[0.0, 0.0, ky], [0.0, 0.0, -kx], [-ky, kx, 0.0]])
        return c * np.eye(3) + s * cross + (1 - c) * np.outer(k, k)

    def to_upright(self, azimuth: ArrayLike, elevation: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Upright azimuth and elevation (radians, any shape) of camera-frame directions."""
        return _angles(np.tensordot(self.matrix(), _unit(azimuth, elevation), axes=1))

    def to_camera(self, azimuth: ArrayLike, elevation: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Camera-frame azimuth and elevation (radians, any shape) of upright directions."""
        return _angles(np.tensordot(self.matrix().T, _unit(azimuth, elevation), axes=1))


def _unit(azimuth: ArrayLike, elevation: ArrayLike) -> FloatArray:
    """Unit vectors (3, ...) of directions (...)."""
    a, e = np.asarray(azimuth, np.float64), np.asarray(elevation, np.float64)
    return np.stack(np.broadcast_arrays(np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)))


def _angles(vectors: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Azimuth and elevation (...) of vectors (3, ...)."""
    x, y, z = vectors
    return np.arctan2(y, x), np.arctan2(z, np.hypot(x, y))


def level_geometry(geometry: PanoramaGeometry, max_deg: float) -> PanoramaGeometry:
    """``geometry`` with whole rows added above and below to reach ``max_deg`` beyond it:
    the upright panorama that every tilt up to ``max_deg`` can be resampled from."""
    extra = math.ceil(math.radians(max_deg) / geometry.row_step) + _SPARE_ROWS
    step = geometry.row_step
    return PanoramaGeometry(
        width=geometry.width,
        height=geometry.height + 2 * extra,
        elevation_top=geometry.elevation_top + extra * step,
        elevation_bottom=geometry.elevation_bottom - extra * step,
        direction=geometry.direction,
        zero_column=geometry.zero_column,
    )


def tilted(
    upright: Float32, source: PanoramaGeometry, target: PanoramaGeometry, tilt: Tilt
) -> Float32:
    """The panorama of ``target`` (its (height, width)) that a camera tilted by ``tilt`` sees,
    resampled (bilinear) from the ``upright`` panorama of ``source`` ((height, width), same
    centre, reaching the tilt's angle beyond ``target``'s elevations: :func:`level_geometry`).
    """
    azimuth, elevation = tilt.to_upright(*target.bearing_grid())
    column = source.azimuth_to_column(azimuth) + _WRAP_COLUMNS
    row = source.elevation_to_row(elevation)
    pad = _WRAP_COLUMNS
    wrapped = np.concatenate([upright[:, -pad:], upright, upright[:, :pad]], axis=1)
    return cv2.remap(
        np.ascontiguousarray(wrapped, dtype=np.float32),
        column.astype(np.float32),
        row.astype(np.float32),
        interpolation=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_REPLICATE,
    )
