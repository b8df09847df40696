"""A registered pairwise method steering a robot: describe, home, and the entry's compass.

Shared by the robot experiments (closed-loop homing towards a goal, route following from
snapshot to snapshot): the robot sees one unfolded panorama at a time, and a method entry's
``compass`` decides whether the method sees it as it is or turned to the goal's heading.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from homebench.experiments.scene import turned
from homebench.geometry import PanoramaGeometry, Pose
from homebench.methods.base import HomingEstimate, checked_estimate
from homebench.methods.image_difference.visual_compass import (
    CompassMode,
    compass_turn,
    in_current_frame,
    whole_columns,
)
from homebench.views import View


@dataclass
class MethodHomer:
    """A registered method homing on unfolded views of ``geometry`` towards ``goal`` features.

    ``compass`` (a method entry's,
    :data:`~homebench.methods.image_difference.visual_compass.CompassMode`):
    ``none``, the method sees the view at the robot's heading and must cope with the rotation
    itself; ``truth``, an external compass: the view is turned to the goal snapshot's heading
    ``goal_heading`` (rad) before the method sees it, as the papers align their views;
    ``visual``, the view is turned back by the visual compass's heading change against
    ``goal_view``. Turns are whole columns; the answer is turned back into the robot's frame.
    """

    method: Any
    goal: Any
    geometry: PanoramaGeometry
    compass: CompassMode = "none"
    goal_heading: float = 0.0
    goal_view: View | None = None
    sees: bool = True

    def estimate(self, pose: Pose, image: NDArray[np.uint8]) -> HomingEstimate:
        """The method's estimate from ``image`` seen at true ``pose``, in the robot's frame;
        TypeError or ValueError when the method answers no estimate (a string, an infinite
        angle: :func:`~homebench.methods.base.checked_estimate`)."""
        view = View(image, self.geometry)
        if self.compass == "none":
            return checked_estimate(self.method.home(self.method.describe(view), self.goal))
        if self.compass == "truth":
            turn = whole_columns(pose.heading - self.goal_heading, self.geometry.width)
        else:
            assert self.goal_view is not None
            turn = compass_turn(view, self.goal_view)
        aligned = View(turned(view, -turn), self.geometry)
        estimate = self.method.home(self.method.describe(aligned), self.goal)
        return in_current_frame(checked_estimate(estimate), turn)

    def direction(self, pose: Pose, image: NDArray[np.uint8] | None) -> float | None:
        """Home direction in the robot frame (rad), or None."""
        assert image is not None
        return self.estimate(pose, image).angle
