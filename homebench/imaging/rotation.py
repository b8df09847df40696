"""Rotate a view as if the robot had turned on the spot (no compass experiments)."""

from __future__ import annotations

import math

import cv2
import numpy as np

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry
from homebench.views import View


def rotate_view(view: View, rotation: float) -> View:
    """The view a robot turned ccw by ``rotation`` radians (same place) would see.

    Unfolded views are rolled by whole columns (``rotation`` must be a multiple of the column
    step, else ValueError); raw views are rotated about the image centre (bilinear).
    """
    geometry = view.geometry
    if isinstance(geometry, PanoramaGeometry):
        shift = geometry.columns_for_rotation(rotation)
        if abs(shift - round(shift)) > 1e-6:
            raise ValueError(f"rotation {rotation} rad is not a whole number of columns")
        return View(np.roll(view.image, round(shift), axis=1), geometry)
    assert isinstance(geometry, CatadioptricGeometry)
    sign = 1.0 if geometry.direction == "ccw" else -1.0
    # Content at azimuth a must move to where azimuth a - rotation is imaged: the image turns by
    # -sign * rotation (ccw as displayed); OpenCV's positive angle is ccw as displayed.
    matrix = cv2.getRotationMatrix2D(geometry.centre, math.degrees(-sign * rotation), 1.0)
    size = (geometry.width, geometry.height)
    rotated = cv2.warpAffine(view.image, matrix, size, flags=cv2.INTER_LINEAR)
    return View(rotated, geometry)
