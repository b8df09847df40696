"""A test world of dark cylinders on a bright background, for the horizon-landmark methods.

Every column of the panorama is one ray fan in azimuth (``SUBSAMPLES`` rays spread evenly across
the column, symmetric about its centre); a ray that meets a cylinder (in front of the camera)
sees ``DARK``, any other ``BRIGHT``; the column's grey level is the mean of its rays, the same in
every row. Symmetric scenes so give mirror-symmetric panoramas, and home directions that follow
from the symmetry exactly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from synthetic_panorama import GEOMETRY

from homebench.geometry import PanoramaGeometry, Pose
from homebench.methods.base import View

DARK = 40.0
BRIGHT = 200.0
SUBSAMPLES = 16
RADIUS = 0.1  # metres, every cylinder

#: Four cylinders around the origin, symmetric about both axes.
CROSS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


def landmark_signal(pose: Pose, landmarks: ArrayLike, n_columns: int) -> np.ndarray:
    """Grey levels (n_columns,) in canonical columns seen from ``pose`` (metres, radians)."""
    centres = np.asarray(landmarks, dtype=np.float64) - pose.xy  # (m, 2)
    offsets = (np.arange(SUBSAMPLES) + 0.5) / SUBSAMPLES - 0.5
    azimuth = 2.0 * np.pi * (np.arange(n_columns)[:, None] + offsets[None, :]) / n_columns
    world = pose.heading + azimuth  # (n, s)
    ux, uy = np.cos(world)[..., None], np.sin(world)[..., None]
    along = ux * centres[:, 0] + uy * centres[:, 1]  # (n, s, m)
    across = np.abs(ux * centres[:, 1] - uy * centres[:, 0])
    hit = np.any((along > 0) & (across < RADIUS), axis=-1)
    return np.where(hit, DARK, BRIGHT).mean(axis=1)


def landmark_view(
    pose: Pose, landmarks: ArrayLike = CROSS, geometry: PanoramaGeometry = GEOMETRY
) -> View:
    """The uint8 view of the cylinders from ``pose`` (a ccw panorama, zero column 0)."""
    signal = landmark_signal(pose, landmarks, geometry.width)
    image = np.rint(np.tile(signal, (geometry.height, 1))).astype(np.uint8)
    return View(image, geometry)
