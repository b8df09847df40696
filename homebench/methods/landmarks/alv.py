"""Average landmark vector (Lambrinos et al. 2000; Möller 2001).

Model (Lambrinos, Möller, Labhart, Pfeifer, Wehner 2000, Robotics and Autonomous Systems 30,
39-64; Möller 2001, Autonomous Robots 10, 225-235): landmarks are the dark sectors of the
thresholded horizon; the average landmark vector (ALV) of a place is the mean of the unit
vectors towards the landmark centres, in a frame fixed to the world. The goal's ALV is all the
agent stores; at the current place the home vector is ``ALV(current) - ALV(goal)``. (The ALV is
roughly the mean landmark position minus the agent's position, scaled, so the difference points
from the current place towards the goal.)

Here both vectors are expressed in the current robot frame, which the papers' external
compass aligns with the goal's: a grid database's common heading is that alignment; a config
entry's ``compass: visual`` (engine level, any method) turns the current view back by the
visual compass's heading change first. The home direction is the angle of the difference.
Segmentation (shared with the snapshot model): :mod:`homebench.methods.landmarks.horizon`,
Otsu's two-class threshold of the horizon signal by default.

No direction without evidence: a view with no landmark sector (a flat or one-sided horizon)
gives :meth:`HomingEstimate.none`; equal ALVs (identical views) give ``angle=None``.

Validation scene (tests/test_validation_alv.py): the papers' black cylinders on a bright wall,
the wall lit 2:1 unevenly (style ``arena``, seeds 0-2, 5 x 5 grids within the four
cylinders, photographed through the camera). The default segmentation finds exactly the
cylinders in every view, and ALV homes as on the world's ground-truth landmarks (``render:
landmarks``): AHC 0.979 against the control's 0.979, estimates 1.8 deg from the control's. The
mean threshold takes the dim wall for landmarks too: AHC 0.910, 18 % of the pairs off by more
than 45 deg.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.methods.base import HomingEstimate, ImageKind
from homebench.methods.landmarks.horizon import (
    LandmarkKind,
    LandmarkViews,
    Sectors,
    vector_direction,
)
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]


def average_landmark_vector(sectors: Sectors) -> FloatArray:
    """Mean unit vector (2,) towards the sector centres (robot frame, x = heading)."""
    return np.array([np.mean(np.cos(sectors.centres)), np.mean(np.sin(sectors.centres))])


@register
@documented
@dataclass(frozen=True)
class AverageLandmarkVector(LandmarkViews):
    """Average landmark vector (Lambrinos et al. 2000; Möller 2001): ALV(current) - ALV(goal)."""

    name: ClassVar[str] = "alv"
    image_kind: ClassVar[ImageKind] = "unfolded"

    landmarks: LandmarkKind = param(
        "dark",
        "Which sectors are landmarks: dark (below the threshold) or bright ones.",
        paper="landmarks are the dark sectors (black cylinders on a bright background); bright "
        "suits scenes whose salient objects are light",
    )

    def __post_init__(self) -> None:
        self.check_landmark_params()

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction: the angle of ALV(current) - ALV(goal), current robot frame; the
        features are horizon signals (n,)."""
        now = self.sectors(current).of_kind(self.landmarks)
        then = self.sectors(goal).of_kind(self.landmarks)
        count = int(now.centres.size + then.centres.size)
        if now.centres.size == 0 or then.centres.size == 0:
            return HomingEstimate.none(n_landmarks=count, reason="no landmarks")
        vector = average_landmark_vector(now) - average_landmark_vector(then)
        return HomingEstimate(
            angle=vector_direction(vector),
            n_landmarks=count,
            score=float(np.hypot(*vector)),
            diagnostics={
                "landmarks_current": int(now.centres.size),
                "landmarks_goal": int(then.centres.size),
            },
        )
