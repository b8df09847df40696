"""Descent in image distances with the neighbouring views of a grid database (DID; Zeil,
Hofmann and Chahl 2003, J. Opt. Soc. Am. A 20(3), 450-469).

Model: the image distance ``D(x) = sqrt(mean((I(x) - S)**2))`` between the view at x and the
snapshot S grows smoothly with the distance from the goal (the translational image difference
function), so the goal lies down its gradient. Zeil et al. measured D on a grid of views around
the goal; a robot estimates the gradient from views a small step apart. Here the grid database
provides those views: the engine hands :meth:`DescentInImageDistances.home` the features of the
current position's grid neighbours (``neighbour_step`` grid units along each grid axis, those
inside the grid) with their offsets in the current robot frame, and the gradient is the
least-squares plane through ``D(neighbour) - D(current)`` over the offsets. The home direction
is that of ``-gradient``, in the current robot frame.

This uses more views than the current one and the goal (like klt-sector's route views): it
is the DID baseline as the papers measured it on image databases, not a two-view method.
Views are compared as they are (the databases are captured at one heading; a rotated current
view and its neighbours share the rotation, so they stay aligned with each other but not with
the goal: DID, like the papers, needs a compass for turned views).

Readings and options (see the parameters): the image (the whole unfolded panorama, as Zeil et
al.; or an elevation band), the RMS difference, the step (one grid unit: 30 cm on the Bielefeld
grid, within the smooth part of the function near and far from the goal). A texture-less
image gives :meth:`HomingEstimate.none`; fewer than two independent offsets (no neighbour in
one axis) or a zero gradient give no direction.

Pre-smoothing (``blur_deg``, shared with MFDID and the visual compass: see
:class:`homebench.methods.image_difference.visual_compass.WholeImageViews`): off by default;
whether and how
Zeil et al. low-pass their images could not be checked here.

Validation (tests/test_validation_did.py), on the paper's scene, an image distance that grows
smoothly from the goal: in rendered panoramas of a round arena with a smooth wall, the goal at
its centre, the RMS difference is 0 at the goal and rises at every 5 cm step along 8
directions out to 1.5 m; descent with neighbours 0.1 m away at 36 places 0.3-0.9 m from the
goal gives AHC 0.997, at most 16 deg.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.methods.base import HomingEstimate, ImageKind, is_flat
from homebench.methods.image_difference.visual_compass import WholeImageViews
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]

#: A neighbouring view: its offset from the current position in the current robot frame
#: (metres, (2,): ahead, left) and its features.
Neighbour = tuple[FloatArray, Any]


def image_distance(image: FloatArray, snapshot: FloatArray) -> float:
    """Root-mean-square grey-level difference of two images of equal shape."""
    return float(np.sqrt(np.mean((image - snapshot) ** 2)))


def distance_gradient(
    offsets: FloatArray, distances: FloatArray, centre: float
) -> FloatArray | None:
    """Least-squares gradient (2,) of the image distance: ``distances`` (n,) at ``offsets``
    (n, 2) metres from the centre, whose distance is ``centre``; None unless the offsets span
    the plane."""
    if len(offsets) < 2 or np.linalg.matrix_rank(offsets) < 2:
        return None
    gradient, *_ = np.linalg.lstsq(offsets, distances - centre, rcond=None)
    return gradient


@register
@documented
@dataclass(frozen=True)
class DescentInImageDistances(WholeImageViews):
    """DID (Zeil, Hofmann and Chahl 2003): the image-distance gradient from the grid neighbours
    of the current view."""

    name: ClassVar[str] = "did"
    image_kind: ClassVar[ImageKind] = "unfolded"
    uses_neighbours: ClassVar[bool] = True

    neighbour_step: int = param(
        1,
        "Grid units between the current position and the neighbours whose views give the "
        "gradient (along each grid axis, both sides where inside the grid).",
        reading="Zeil et al. sampled image differences on a 10 cm grid around the goal; a grid "
        "database's own spacing is the smallest step it offers",
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.neighbour_step < 1:
            raise ConfigError(f"{self.name}: neighbour_step must be at least 1")

    def home(
        self, current: FloatArray, goal: FloatArray, neighbours: Sequence[Neighbour] = ()
    ) -> HomingEstimate:
        """Home direction: minus the image-distance gradient fitted over ``neighbours``."""
        if is_flat(current) or is_flat(goal):
            return HomingEstimate.none(reason="no texture")
        centre = image_distance(current, goal)
        offsets = np.array([offset for offset, _ in neighbours], dtype=float).reshape(-1, 2)
        distances = np.array([image_distance(image, goal) for _, image in neighbours])
        gradient = distance_gradient(offsets, distances, centre)
        if gradient is None or not np.any(gradient):
            return HomingEstimate(None, n_landmarks=len(neighbours), score=centre)
        return HomingEstimate(
            angle=float(np.arctan2(-gradient[1], -gradient[0])),
            n_landmarks=len(neighbours),
            score=centre,
            diagnostics={"gradient": gradient.tolist()},
        )
