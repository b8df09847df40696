"""Route-learning methods steering a robot (perfect-memory, infomax): entries, training, steering.

Shared by the robot experiments. A method that learns a route (``learns_route``, the protocol of
:mod:`homebench.methods.familiarity.route_memory`) does not home from a pair of views: it learns
the views of
a route, each facing the way to go, and steers by the most familiar direction of its memory.
So its method entry passes other checks than a pairwise method's: it gives no direction on a
pair (``gives_direction = False``) yet steers a robot, and it needs no compass (it turns its
view through every rotation itself).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from homebench.config import MethodEntry, entry_error, entry_problem, value_problem
from homebench.errors import ConfigError, HomebenchError
from homebench.experiments.scene import turned
from homebench.geometry import PanoramaGeometry, Pose
from homebench.methods import registry
from homebench.methods.base import HomingEstimate
from homebench.methods.familiarity.route_memory import learns_route
from homebench.views import View


def is_memory_method(name: str) -> bool:
    """Whether method ``name`` learns a route (False for an unknown name: its entry's check
    names it)."""
    try:
        return learns_route(registry.get(name))
    except HomebenchError:
        return False


def robot_entry_error(k: int, entry: MethodEntry, robot: str) -> str:
    """What is wrong with ``entry``, the ``k``-th method entry of a ``robot`` experiment, in one
    line that starts with its key; "" when nothing is. Pairwise methods: the grid config's
    checks (:func:`homebench.config.entry_error`); route-learning methods: their parameters,
    unfolded images and no compass."""
    if not is_memory_method(entry.method):
        return entry_error(k, entry, robot)
    wrong = value_problem(entry)
    if wrong:
        return f"methods.{k}.{wrong}"
    problem = entry_problem(entry)
    if not problem and entry.compass != "none":
        problem = (
            f"{entry.method} learns a route and turns its view through every rotation itself; "
            "its entry takes no compass"
        )
    if not problem and registry.get(entry.method).image_kind != "unfolded":
        problem = f"{entry.method} needs unfolded panoramas, which a {robot} robot sees"
    return f"methods.{k}: {problem}" if problem else ""


def check_robot_entries(path: Any, entries: Sequence[MethodEntry], robot: str) -> None:
    """ConfigError naming the file and the first entry with a problem
    (:func:`robot_entry_error`)."""
    for k, entry in enumerate(entries):
        problem = robot_entry_error(k, entry, robot)
        if problem:
            raise ConfigError(f"{path}: {problem}")


def facing(image: NDArray[np.uint8], geometry: PanoramaGeometry, turn: float) -> View:
    """The view of ``image`` turned ccw by ``turn`` (rad, whole columns): what the camera sees
    at the same place facing ``turn`` further left (a panorama holds every heading)."""
    return View(turned(View(image, geometry), turn), geometry)


@dataclass(frozen=True)
class MemoryGuide:
    """A route-learning ``method`` with its ``memory``, steering on unfolded views of
    ``geometry``: the most familiar direction of the view seen at a pose (robot frame);
    ``sees``: as a closed-loop homer, it needs the view at the pose."""

    method: Any
    memory: Any
    geometry: PanoramaGeometry
    sees: bool = True

    @classmethod
    def trained(cls, method: Any, views: Sequence[View], geometry: PanoramaGeometry) -> MemoryGuide:
        """``method`` trained on ``views`` (route order, each facing the way to go)."""
        return cls(method, method.learn([method.describe(view) for view in views]), geometry)

    def estimate(self, pose: Pose, image: NDArray[np.uint8]) -> HomingEstimate:
        """The method's ``follow`` on ``image`` (the pose is not used: the robot sees only)."""
        return self.method.follow(self.memory, self.method.describe(View(image, self.geometry)))

    def direction(self, pose: Pose, image: NDArray[np.uint8] | None) -> float | None:
        """Most familiar direction in the robot frame (rad), or None (a closed-loop homer)."""
        assert image is not None
        return self.estimate(pose, image).angle
