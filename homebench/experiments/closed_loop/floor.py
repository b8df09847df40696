"""The floor plan a closed-loop run is drawn on: the room and the objects' footprints.

A generated world gives its room and every object's footprint outline; an object is an
obstacle when it spans the camera's height (the robot collides where the camera would enter
it, :meth:`~homebench.data.synth.world.World.check_pose`). A grid database knows no objects:
its plan is the capture grid's extent plus one spacing (where the robot may drive).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import MIN_CLEARANCE, build_world
from homebench.geometry import FloatArray, Grid


@dataclass(frozen=True)
class FloorPlan:
    """``bounds`` (x_min, y_min, x_max, y_max) metres; ``outlines``: footprints (n, 2) each;
    ``obstacles``: whether each spans the camera's height."""

    bounds: tuple[float, float, float, float]
    outlines: tuple[FloatArray, ...] = ()
    obstacles: tuple[bool, ...] = ()


def world_plan(spec: WorldSpec) -> FloorPlan:
    """The room of ``spec`` and its objects' footprints."""
    world = build_world(spec)
    room, z = world.scene.room, spec.camera_height
    objects = world.scene.objects
    return FloorPlan(
        (0.0, 0.0, room.width, room.depth),
        tuple(np.asarray(o.outline(), dtype=np.float64) for o in objects),
        tuple(bool(o.z0 - MIN_CLEARANCE < z < o.z1 + MIN_CLEARANCE) for o in objects),
    )


def grid_plan(grid: Grid) -> FloorPlan:
    """A grid database's drivable extent: its grid plus one spacing around."""
    far = grid.position(grid.shape[0] - 1, grid.shape[1] - 1)
    s = grid.spacing
    return FloorPlan((grid.origin[0] - s, grid.origin[1] - s, float(far[0]) + s, float(far[1]) + s))
