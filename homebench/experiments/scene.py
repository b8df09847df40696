"""Where a robot drives (route and closed-loop experiments): a generated world, a grid database,
or a database of posed images.

In a generated world the robot sees the panorama rendered at its true pose. On a grid database
it sees the image of the grid position nearest to it, turned to its heading by whole columns
(seed 000's experiment "on the nearest grid images"); it may not leave the grid by more than
one spacing. On a database of posed images that is no grid (a recorded route in the Brains on
Board format) it sees the recorded image nearest to it, turned the same way: a route driven
along the recording replays its images. It may not go farther from every recorded pose than
the recording's sparsest spacing (the largest distance from a recorded pose to its nearest
neighbour), the rule of the grid's one spacing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from homebench.config import UnfoldConfig
from homebench.data import catalog
from homebench.data.bob import open_bob
from homebench.data.database import GridDatabase
from homebench.data.posed import PosedDatabase
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import PoseError, build_world
from homebench.evaluation.sources import content_key, database_view, real_identity, unfolded_view
from homebench.geometry import (
    Grid,
    PanoramaGeometry,
    Places,
    Pose,
    nearest_distances,
    wrap_angle,
)
from homebench.hashing import derived_seed, stable_hash
from homebench.imaging.rotation import rotate_view
from homebench.views import View

#: A robot's camera: the panorama (H, W) or (H, W, 3), uint8, seen at a pose as frame k.
Camera = Callable[[Pose, int], NDArray[np.uint8]]


@dataclass(frozen=True)
class Scene:
    """How the robot sees (unfolded panoramas of ``geometry``) and where it may go.

    ``render(pose, noise_seed)`` gives the panorama at ``pose``; ``check_pose`` raises PoseError
    for a pose the scene cannot show; ``grid_origin`` is the capture grid's origin (metres),
    which routes given in the grid frame start from; ``grid`` the capture grid itself;
    ``recorded`` the poses of a database of posed images, in recording order (``waypoints:
    recorded`` routes follow them).
    """

    geometry: PanoramaGeometry
    render: Callable[[Pose, int], NDArray[np.uint8]]
    check_pose: Callable[[Pose], None]
    grid_origin: tuple[float, float]
    grid: Grid | None = None
    recorded: PosedDatabase | None = None

    def camera(self, seed: int, phase: str) -> Camera:
        """Frame k at ``pose``, its sensor noise seeded by (seed, phase, k)."""

        def take(pose: Pose, k: int) -> NDArray[np.uint8]:
            return self.render(pose, derived_seed(seed, phase, k))

        return take


def world_scene(spec: WorldSpec) -> Scene:
    world = build_world(spec)
    return Scene(
        world.unfolded_geometry,
        lambda pose, noise_seed: world.render(pose, noise_seed)["unfolded"],
        world.check_pose,
        spec.to_grid().origin,
        spec.to_grid(),
    )


@lru_cache(maxsize=4)
def _database(locator: str, path: Path | None) -> GridDatabase:
    database = catalog.resolve(locator, path)
    database.check_layout()
    return database


def grid_scene(locator: str, path: Path | None, unfold: UnfoldConfig) -> Scene:
    """Nearest grid images of a database (a known name or manifest path), turned to the pose."""
    database = _database(locator, path)
    grid = database.grid
    unfold_geometry = None if "unfolded" in database.kinds else unfold.geometry()
    first = next(grid.indices())  # a grid with holes may have no image at (0, 0)
    geometry = database_view(database, *first, "unfolded", unfold_geometry).geometry
    assert isinstance(geometry, PanoramaGeometry)

    def check_pose(pose: Pose) -> None:
        low = np.asarray(grid.origin) - grid.spacing
        high = np.asarray(grid.position(grid.shape[0] - 1, grid.shape[1] - 1)) + grid.spacing
        if not (np.all(pose.xy >= low) and np.all(pose.xy <= high)):
            raise PoseError(
                f"pose ({pose.x:.2f}, {pose.y:.2f}) m is more than one spacing outside the grid "
                f"of database {database.name!r}",
                "outside",
            )

    def render(pose: Pose, noise_seed: int) -> NDArray[np.uint8]:
        check_pose(pose)
        i, j = (int(v) for v in grid.nearest_index(pose.xy))
        view = database_view(database, i, j, "unfolded", unfold_geometry)
        return turned(view, pose.heading - database.heading(i, j))

    return Scene(geometry, render, check_pose, grid.origin, grid)


def posed_scene(
    posed: PosedDatabase, unfold_config: UnfoldConfig, reach_m: float | None = None
) -> Scene:
    """The recorded image nearest to the pose, turned to it (see the module docstring); raw
    images are unfolded with ``unfold_config``. ``reach_m``: how far from every recorded pose
    the scene still shows the nearest image (default: the recording's sparsest spacing)."""
    unfold_geometry = None if posed.kind == "unfolded" else unfold_config.geometry()
    geometry = posed_view(posed, 0, unfold_geometry).geometry
    assert isinstance(geometry, PanoramaGeometry)
    places = Places.of(posed.xy)
    reach = sparsest_spacing(places.points) if reach_m is None else reach_m
    what = "its sparsest spacing" if reach_m is None else "the config's recorded_reach_m"

    def nearest(pose: Pose) -> int:
        k = int(places.nearest_index(pose.xy)[0])
        distance = math.dist(places.xy[k], pose.xy)
        if not distance <= reach + 1e-9:
            raise PoseError(
                f"pose ({pose.x:.2f}, {pose.y:.2f}) m is {distance:.2f} m from the nearest "
                f"recorded image of database {posed.name!r}, farther than {what} ({reach:.2f} m)",
                "outside",
            )
        return k

    def render(pose: Pose, noise_seed: int) -> NDArray[np.uint8]:
        k = nearest(pose)
        view = posed_view(posed, k, unfold_geometry)
        return turned(view, pose.heading - math.radians(float(posed.heading_deg[k])))

    def check_pose(pose: Pose) -> None:
        nearest(pose)

    return Scene(geometry, render, check_pose, places.origin, recorded=posed)


def sparsest_spacing(xy: NDArray[np.float64]) -> float:
    """The largest distance (metres) from a pose of ``xy`` (n, 2) to its nearest other pose
    (:func:`~homebench.geometry.nearest_distances`); 0 for fewer than two distinct poses."""
    nearest = nearest_distances(xy)
    return float(nearest.max()) if nearest.size else 0.0


def posed_view(posed: PosedDatabase, k: int, unfold_geometry: PanoramaGeometry | None) -> View:
    """Recorded image ``k`` as an unfolded panorama (raw ones unfolded to ``unfold_geometry``)."""
    view = posed.view(k)
    return view if unfold_geometry is None else unfolded_view(view, unfold_geometry)


def turned(view: View, turn: float) -> NDArray[np.uint8]:
    """The image of unfolded ``view`` turned ccw by ``turn`` (rad) rounded to whole columns
    (the heading error this leaves is at most half a column step)."""
    geometry = view.geometry
    assert isinstance(geometry, PanoramaGeometry)
    columns = round(float(wrap_angle(turn)) / geometry.column_step)
    return rotate_view(view, columns * geometry.column_step).image if columns else view.image


def open_scene(
    world: WorldSpec,
    database: str | None,
    database_path: Path | None,
    unfold: UnfoldConfig,
    reach_m: float | None = None,
) -> Scene:
    """The scene of an experiment config: its ``database`` if it names one (a known name,
    manifest path or Brains on Board folder; raw images unfolded with ``unfold``): a grid's
    nearest images, or a recording's (a database of posed images that is no grid, shown within
    ``reach_m``: see :func:`posed_scene`); else its generated ``world``."""
    if database is None:
        return world_scene(world)
    folder = catalog.bob_folder(database, database_path)
    if folder is not None:
        posed = _posed(folder)
        if posed.grid is None:
            return posed_scene(posed, unfold, reach_m)
    return grid_scene(database, database_path, unfold)


@lru_cache(maxsize=4)
def _posed(folder: Path) -> PosedDatabase:
    posed = open_bob(folder)
    posed.check_images()
    return posed


@lru_cache(maxsize=8)
def database_content(locator: str, path: Path | None) -> str:
    """16 hex digits naming what an experiment's database shows the robot, for trial keys: a
    generated set's spec; a real set's identity (folder, manifest, a recording's poses:
    :func:`~homebench.evaluation.sources.real_identity`) and its images' sha256s (hashed once,
    kept by path, size and mtime), as grid runs key them. Kept in this process until
    :func:`forget_databases`."""
    database = _database(locator, path)
    generator = database.manifest.generator
    if generator is not None:
        return stable_hash(generator.spec.key(), 16)
    return stable_hash([real_identity(database), content_key(database, database.kinds)], 16)


def forget_databases() -> None:
    """Drop what this process keeps of experiment databases (content keys, recordings), so
    that a run starting now reads them as they are: an image or a pose corrected since the
    last run gives its trials new keys."""
    database_content.cache_clear()
    _database.cache_clear()
    _posed.cache_clear()
