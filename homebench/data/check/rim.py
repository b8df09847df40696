"""The mirror's rim in raw catadioptric images: a circle whose centre is the mirror axis.

The mean of several raw images keeps what every image shares: a bright disc (the mirror)
on the darker camera housing or black border around it. Otsu's threshold splits the mean
into disc and surround; the outer contour of the largest bright region is fitted with a
circle (algebraic least squares, then twice again without the points more than three
median deviations off it). Contour points on the image border (a mirror cut by the frame)
are left out.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

#: Contour points left for a fit: fewer and there is no circle to speak of.
MIN_POINTS = 20
#: Re-fits without the outlying contour points.
REFITS = 2


@dataclass(frozen=True)
class Circle:
    """A circle in pixel coordinates: ``centre`` (u, v) and ``radius``, pixels."""

    centre: tuple[float, float]
    radius: float


def fit_circle(points: NDArray[np.float64]) -> Circle:
    """Algebraic least-squares circle through ``points`` (n, 2) of (u, v)."""
    u, v = points[:, 0], points[:, 1]
    design = np.column_stack([u, v, np.ones_like(u)])
    (a, b, c), *_ = np.linalg.lstsq(design, u * u + v * v, rcond=None)
    centre = (a / 2.0, b / 2.0)
    return Circle((float(centre[0]), float(centre[1])), float(np.sqrt(c + a * a / 4 + b * b / 4)))


def rim_points(mean: NDArray[np.uint8]) -> NDArray[np.float64]:
    """Outer contour (n, 2) of the largest region brighter than Otsu's threshold of ``mean``
    (height, width), without the points on the image border."""
    _, mask = cv2.threshold(mean, 0, 1, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask)
    if n < 2:
        return np.empty((0, 2))
    largest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    region = (labels == largest).astype(np.uint8)
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    points = max(contours, key=len)[:, 0, :].astype(np.float64)
    h, w = mean.shape
    inside = (points[:, 0] > 0) & (points[:, 1] > 0) & (points[:, 0] < w - 1)
    return points[inside & (points[:, 1] < h - 1)]


def mirror_rim(images: Sequence[NDArray[np.uint8]]) -> Circle | None:
    """The rim circle of raw images (each (height, width) uint8), or None when their mean
    shows no bright region with enough outline, or one centred off the image."""
    mean = np.rint(np.mean(np.stack(images), axis=0)).astype(np.uint8)
    points = rim_points(mean)
    if len(points) < MIN_POINTS:
        return None
    circle = fit_circle(points)
    for _ in range(REFITS):
        off = np.abs(np.hypot(*(points - circle.centre).T) - circle.radius)
        kept = points[off <= 3.0 * np.median(off) + 0.5]
        if len(kept) < MIN_POINTS:
            break
        circle = fit_circle(kept)
    (u, v), (h, w) = circle.centre, mean.shape
    return circle if 0 <= u <= w - 1 and 0 <= v <= h - 1 else None
