"""Matched-filter descent in image distances (Möller and Vardy 2006, Biol. Cybern. 95, 413-430).

Model: the image distance ``D(x) = sum (C(x) - S)**2`` between the current image C at position
x and the snapshot S grows smoothly with the distance from the goal, so the goal lies down its
gradient. Instead of sampling D at exploratory positions, the gradient is predicted from the
current image alone with two matched filters: the image changes ``dC/dx`` and ``dC/dy`` that
small translations along the robot's x (heading) and y axes would cause if every point were at
one distance r (equal-distance assumption):

    ``dC/dx = -sin(phi) / r * dC/dphi``,  ``dC/dy = cos(phi) / r * dC/dphi``

at azimuth ``phi`` (a point at azimuth phi and distance r moves in azimuth by ``sin(phi)/r``
per unit step along x, by ``-cos(phi)/r`` along y), so
``grad D = 2 * sum (C - S) * (dC/dx, dC/dy)`` and the home direction is that of ``-grad D``
(r > 0 drops out). The images must be aligned: the paper's databases are captured at one
heading, as a grid database is; a config entry's ``compass: visual`` (engine level, any method,
:data:`homebench.methods.image_difference.visual_compass.CompassMode`) turns a current view back by
the visual
compass first. The paper has no compass step: a compass error of a few degrees adds an image
difference the matched filters read as a translation. The direction is in the current robot
frame.

Readings and options (see the parameters): the images (whole unfolded panoramas, canonical
columns); the azimuthal derivative (central difference of neighbouring columns, periodic); only
the azimuthal component of the flow enters the filters (points at one horizontal distance; no
elevation flow). Vardy's own MFDID code (a public copy was read; the paper's text was not)
uses the full flow of points at one distance on a sphere instead: the azimuthal term divided
by cos(elevation) plus an elevation term ``cos(phi) sin(elevation)`` on the vertical image
derivative; within the +-30 to 50 deg of an unfolded panorama the azimuthal weights differ
by up to a factor 1.5. A texture-less image gives :meth:`HomingEstimate.none`; a zero
gradient (identical views) ``angle=None``.

Pre-smoothing (``blur_deg``, shared with DID and the visual compass: see
:class:`homebench.methods.image_difference.visual_compass.WholeImageViews`): off by default;
whether and how the
paper low-passes its images could not be checked here.

Validation (tests/test_validation_mfdid.py), on the paper's scene, every point at one distance
and an image distance that grows smoothly: at the centre of a ray-traced landmark ring the
matched filters predict the image change of a small step to 1 % and the direction is the
descent of the true image distance (within 1 deg); rendered panoramas near the goal at the
centre of a round arena with a smooth wall (36 places 0.15-0.6 m away, aligned views) give AHC
0.9985, at most 7.4 deg (at 1.2 m, beyond the first-order range, AHC 0.75).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import TWO_PI
from homebench.methods.base import HomingEstimate, ImageKind, is_flat
from homebench.methods.image_difference.visual_compass import WholeImageViews
from homebench.methods.params import documented
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]


def azimuth_derivative(image: FloatArray) -> FloatArray:
    """dI/dphi per radian (same shape as ``image``, (rows, n)): periodic central difference."""
    n = image.shape[-1]
    return (np.roll(image, -1, axis=-1) - np.roll(image, 1, axis=-1)) * (n / (2.0 * TWO_PI))


def distance_gradient(current: FloatArray, snapshot: FloatArray) -> FloatArray:
    """``r/2 * grad D`` (2,) by the matched filters, robot frame of the current image.

    ``current``, ``snapshot``: aligned images (rows, n), canonical columns."""
    n = current.shape[-1]
    phi = TWO_PI * np.arange(n) / n
    weighted = np.sum((current - snapshot) * azimuth_derivative(current), axis=0)  # (n,)
    return np.array([-np.sum(weighted * np.sin(phi)), np.sum(weighted * np.cos(phi))])


@register
@documented
@dataclass(frozen=True)
class MatchedFilterDescent(WholeImageViews):
    """MFDID (Möller and Vardy 2006): descent in the image distance, gradient by matched
    filters."""

    name: ClassVar[str] = "mfdid"
    image_kind: ClassVar[ImageKind] = "unfolded"

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction: minus the matched-filter gradient of the image distance."""
        if current.shape != goal.shape:
            raise ValueError("mfdid: current and goal images differ in shape")
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(n_landmarks=int(current.size), reason="no texture")
        gradient = distance_gradient(current, goal)
        angle = float(np.arctan2(-gradient[1], -gradient[0])) if np.any(gradient) else None
        return HomingEstimate(
            angle=angle,
            n_landmarks=int(current.size),
            score=float(np.sqrt(np.mean((current - goal) ** 2))),
            diagnostics={"gradient": gradient.tolist()},
        )
