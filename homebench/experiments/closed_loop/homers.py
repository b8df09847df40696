"""What steers a closed-loop robot: a registered pairwise method, or one of two controls.

**Controls** (built-in pseudo-methods of the closed-loop kind, not registered grid methods:
they need the true pose, which no grid method sees) bound every method from both sides:

- ``truth`` returns the true home direction (:func:`homebench.geometry.home_direction`). With
  the robot of :func:`~homebench.experiments.robot.steer` (turn on the spot until the direction
  lies within one turn, then turn onto it and drive straight) it drives a straight line home:
  success 1.0 and a path ratio within one step of 1 (see :mod:`~.loop`) without motion noise.
- ``random`` returns a direction uniform in [-pi, pi), seeded per trial: a random walk whose
  success rate is the chance level of the start distances, budget and success radius.

Neither renders a view. A **method** homes on unfolded panoramas
(:class:`~homebench.experiments.homing.MethodHomer`): the goal snapshot is described once per
goal (and method, and process), the current view every step, then ``home(current, goal)``;
a method that tracks features along a route (klt-sector) homes pairwise here, with no
intermediate views (its ``route`` empty). Methods that take the views as aligned (no rotation
estimate of their own: alv, mfdid, snapshot, block-matching) need
a ``compass`` (their entry's ``compass: truth``, the papers' external compass, or ``visual``) to
home from a start whose heading differs from the goal's: without it their answer does not turn
with the robot, which then turns on the spot for ever.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from homebench.experiments.homing import MethodHomer
from homebench.geometry import Pose, home_direction


class Homer(Protocol):
    """Gives the home direction at a pose; ``sees``: whether it needs the view there."""

    sees: bool

    def direction(self, pose: Pose, image: np.ndarray | None) -> float | None:
        """Home direction in the robot frame (rad, ccw, 0 = heading), or None."""
        ...


@dataclass
class TruthHomer:
    """The ``truth`` control: the true home direction towards ``goal``."""

    goal: Pose
    sees: bool = False

    def direction(self, pose: Pose, image: np.ndarray | None) -> float | None:
        return float(home_direction(pose.xy, self.goal.xy, pose.heading))


@dataclass
class RandomHomer:
    """The ``random`` control: a direction uniform in [-pi, pi) from ``rng``."""

    rng: np.random.Generator
    sees: bool = False

    def direction(self, pose: Pose, image: np.ndarray | None) -> float | None:
        return float(self.rng.uniform(-math.pi, math.pi))


__all__ = ["Homer", "MethodHomer", "RandomHomer", "TruthHomer"]
