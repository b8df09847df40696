"""Brains on Board image databases written by hand, as BoB robotics' Ant World tools leave them.

The images are the analytic arena (tests/synthetic_panorama.py, with the rich wall of
tests/validation_scenes.py, on which min-warping homes: its own wall repeats every 120 deg once
edge-filtered) laid out as BoB's Ant World
renderer lays out its panoramas, by BoB's formula, not homebench's camera model: column c of a
W-wide image with recorded heading h looks along the compass bearing ``h + 360 (c + 0.5 -
W/2) / W`` (clockwise from +y), row r of an H-high one at elevation ``60 - 75 (r + 0.5) / H``
(BoB's ``src/antworld/render_mesh.cc`` and ``renderer.cc``; homebench/data/bob/conventions.py
says how that was read and checked on BoB's own images). Headings are compass bearings; a
route's are computed from its positions by BoB's ``RouteContinuous`` formula (``90 +
atan2(start.y - end.y, end.x - start.x)`` of the segment an image lies on), so the camera faces
the way it travels. Images are written with cv2; the CSV and the metadata are typed text:
spaces after the commas, positions in mm, headings in degrees and not all equal, OpenCV's
``%YAML:1.0`` line and a ``!!opencv-matrix``. No homebench code writes any of it, so a reading
bug of homebench's cannot cancel out.

Real recordings have holes, and the writers make them: a grid capture that failed (no row, no
image), a row whose pose was lost (BoB's ``dataset_recorder`` writes ``nan`` where the GPS gave
no fix; pandas writes an empty cell), a block of labels cut from a larger recorder grid.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np
from synthetic_panorama import render_rays
from validation_scenes import rich_texture

#: BoB's Ant World images are 720 x 150 (ant_world_db_creator's RenderSize): these, of the same
#: field of view (360 x 75 deg), are 288 x 60.
WIDTH, HEIGHT = 288, 60
GRID_SHAPE = (5, 5)
SPACING_MM = 300.0
ORIGIN_MM = (-600.0, -450.0)
Z_MM = 10.0
HEADING_DEG = 30.0
#: Images taken at another heading than the rest.
TURNED_DEG = {(1, 2): 75.0, (3, 3): -20.0, (4, 0): 200.0}
#: The route: poses on an arc around the arena centre, each facing along it.
ROUTE_POSES = 10


def bob_bearings_deg(heading_deg: float) -> np.ndarray:
    """Compass bearing (deg, clockwise from +y) each column of a BoB Ant World image with
    recorded heading ``heading_deg`` looks along, shape (WIDTH,)."""
    return heading_deg + 360.0 * (np.arange(WIDTH) + 0.5 - WIDTH / 2) / WIDTH


def bob_elevations_deg() -> np.ndarray:
    """Elevation (deg) of each row of a BoB Ant World image, shape (HEIGHT,)."""
    return 60.0 - 75.0 * (np.arange(HEIGHT) + 0.5) / HEIGHT


def bob_image(x_mm: float, y_mm: float, heading_deg: float) -> np.ndarray:
    """The arena seen from (x, y) mm with compass heading ``heading_deg``, laid out as BoB's
    Ant World renders: (HEIGHT, WIDTH) uint8."""
    world = np.radians(90.0 - bob_bearings_deg(heading_deg))  # ccw from +x
    elevations = np.radians(bob_elevations_deg())
    grey = render_rays(x_mm / 1000.0, y_mm / 1000.0, world, elevations, rich_texture)
    return np.rint(grey).astype(np.uint8)


GRID_METADATA = """\
%YAML:1.0
---
metadata:
   time: "2019-01-29 13:05:14"
   project_git_commit: "0123abc (not dirty)"
   type: grid
   grid:
      beginAtMM: [ -600., -450., 10. ]
      separationMM: [ 300., 300., 0. ]
      size: [ 5, 5, 1 ]
   camera:
      name: opengl
      resolution: [ 288, 60 ]
      isPanoramic: 0
   needsUnwrapping: 0
   isGreyscale: 0
   calibration: !!opencv-matrix
      rows: 2
      cols: 2
      dt: d
      data: [ 1., 0., 0., 1. ]
"""

ROUTE_METADATA = """\
%YAML:1.0
---
metadata:
   time: "2024-05-02 10:11:12"
   type: route
   camera:
      name: opengl
      resolution: [ 288, 60 ]
      isPanoramic: 0
   needsUnwrapping: 0
"""


def grid_name(x_mm: float, y_mm: float) -> str:
    """BoB's file name of a grid image: ``image_+000300_-000450_+000010.png``."""
    return "image_" + "_".join(f"{round(v):+07d}" for v in (x_mm, y_mm, Z_MM)) + ".png"


def grid_position_mm(i: int, j: int) -> tuple[float, float]:
    return ORIGIN_MM[0] + i * SPACING_MM, ORIGIN_MM[1] + j * SPACING_MM


def grid_heading_deg(i: int, j: int) -> float:
    return TURNED_DEG.get((i, j), HEADING_DEG)


def _write_image(path: Path, x_mm: float, y_mm: float, heading_deg: float, colour: bool) -> None:
    image = bob_image(x_mm, y_mm, heading_deg)
    if colour:  # a recorder's colour image: homebench reads it as grey
        image = np.repeat(image[:, :, None], 3, axis=2)
    assert cv2.imwrite(str(path), image)


#: The cells of a row that lost its pose, as recorders write them: BoB's ``dataset_recorder``
#: writes ``nan`` where the GPS gave no position, pandas an empty cell.
LOST_CELL = {"X": "nan", "Y": "nan", "Heading": ""}


def _cells(values: dict[str, float], lost: Sequence[str]) -> str:
    """``X, Y, Z, Heading`` of a row (mm, degrees), the ``lost`` ones (of X, Y, Heading) as
    :data:`LOST_CELL` writes them."""
    shown = {name: LOST_CELL[name] if name in lost else f"{v:g}" for name, v in values.items()}
    return f"{shown['X']}, {shown['Y']}, {Z_MM:g}, {shown['Heading']}"


def write_grid(
    folder: Path,
    failed: Collection[tuple[int, int]] = (),
    lost: Mapping[tuple[int, int], Sequence[str]] | None = None,
) -> Path:
    """A 5 x 5 grid database in ``folder``, rows in no grid order, a pitch, a roll and a
    timestamp column among the standard ones; ``folder``. The captures at ``failed`` positions
    left neither a row nor an image; those at ``lost`` positions lost the values named (of X,
    Y, Heading), their images taken where they belong."""
    folder.mkdir(parents=True, exist_ok=True)
    lines = [
        "X [mm], Y [mm], Z [mm], Heading [degrees], Pitch [degrees], Roll [degrees], "
        "Filename, Grid X, Grid Y, Grid Z, Timestamp [ms]"
    ]
    cells = [(i, j) for j in range(GRID_SHAPE[1]) for i in range(GRID_SHAPE[0])]
    order = np.random.default_rng(7).permutation(len(cells))
    for n, k in enumerate(order):
        i, j = cells[k]
        if (i, j) in failed:
            continue
        x, y = grid_position_mm(i, j)
        heading = grid_heading_deg(i, j)
        name = grid_name(x, y)
        _write_image(folder / name, x, y, heading, colour=(i, j) == (2, 2))
        pose = _cells({"X": x, "Y": y, "Heading": heading}, (lost or {}).get((i, j), ()))
        lines.append(f"{pose}, nan, 0, {name}, {i}, {j}, 0, {n * 40}")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (folder / "database_metadata.yaml").write_text(GRID_METADATA)
    return folder


def recorder_images(
    shape: tuple[int, int], block: tuple[range, range] | None = None
) -> dict[tuple[int, int], tuple[float, float]]:
    """Label -> where it was rendered (mm) of each image BoB's ant_world_db_creator records on
    a grid of ``shape`` (nx, ny), in recording order: image k rendered at the k-th position of
    ``GridRecorder::getPositions()`` (x outer, y inner: (k // ny, k % ny)) and labelled by
    ``GridRecorder::record(image)`` (k % nx, k // nx); those labelled inside ``block`` (Grid X,
    Grid Y ranges) only, where given."""
    nx, ny = shape
    images = {(k % nx, k // nx): grid_position_mm(k // ny, k % ny) for k in range(nx * ny)}
    if block is None:
        return images
    return {(a, b): taken for (a, b), taken in images.items() if a in block[0] and b in block[1]}


def write_recorder_grid(
    folder: Path, shape: tuple[int, int], block: tuple[range, range] | None = None
) -> Path:
    """A grid database of ``shape`` (nx, ny) in ``folder`` as BoB's ant_world_db_creator
    leaves one (heading 0): the images of :func:`recorder_images`, each row with the position
    ``GridRecorder::record`` writes, that of its label; rows in recording order; ``folder``.
    ``block``: only the rows labelled inside it (Grid X, Grid Y ranges), as a block cut from
    the grid; the metadata keeps the grid's size."""
    folder.mkdir(parents=True, exist_ok=True)
    nx, ny = shape
    lines = ["X [mm], Y [mm], Z [mm], Heading [degrees], Filename, Grid X, Grid Y, Grid Z"]
    for (a, b), taken in recorder_images(shape, block).items():
        x, y = grid_position_mm(a, b)
        name = grid_name(x, y)
        _write_image(folder / name, *taken, 0.0, colour=False)
        lines.append(f"{x:g}, {y:g}, {Z_MM:g}, 0, {name}, {a}, {b}, 0")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    metadata = GRID_METADATA.replace("size: [ 5, 5, 1 ]", f"size: [ {nx}, {ny}, 1 ]")
    (folder / "database_metadata.yaml").write_text(metadata)
    return folder


def arc_points() -> list[tuple[float, float]]:
    """The default route's points (mm): an arc of radius 1 m from 0 to 90 deg about the
    arena's centre, travelled counter-clockwise."""
    points = []
    for k in range(ROUTE_POSES):
        angle = math.radians(90.0 * k / (ROUTE_POSES - 1))
        points.append((round(1000.0 * math.cos(angle), 2), round(1000.0 * math.sin(angle), 2)))
    return points


def bend_points(step_mm: float = 50.0) -> list[tuple[float, float]]:
    """A route with straight stretches and a bend (mm), a point every ``step_mm``: east from
    (-1200, -900) to (0, -900), a left quarter turn of radius 600 mm about (0, -300), then
    north from (600, -300) to (600, 900)."""
    points = [(-1200.0 + d, -900.0) for d in np.arange(0.0, 1200.0, step_mm)]
    turn = int(round(math.pi / 2 * 600.0 / step_mm))
    points += [
        (600.0 * math.sin(a), -300.0 - 600.0 * math.cos(a))
        for a in np.linspace(0.0, math.pi / 2, turn, endpoint=False)
    ]
    points += [(600.0, -300.0 + d) for d in np.arange(0.0, 1200.0 + 1e-9, step_mm)]
    return [(round(float(x), 2), round(float(y), 2)) for x, y in points]


def route_poses(
    points: list[tuple[float, float]] | None = None,
) -> list[tuple[float, float, float]]:
    """(x mm, y mm, compass heading deg) of the route through ``points`` (mm; default
    :func:`arc_points`); each image's heading is that of the segment it starts (the last
    one's, of the segment it ends), by BoB's formula (``RouteContinuous``: ``90 +
    atan2(start.y - end.y, end.x - start.x)``)."""
    points = arc_points() if points is None else points
    poses = []
    for k, (x, y) in enumerate(points):
        (x0, y0), (x1, y1) = points[k : k + 2] if k + 1 < len(points) else points[k - 1 : k + 1]
        heading = (90.0 + math.degrees(math.atan2(y0 - y1, x1 - x0))) % 360.0
        poses.append((x, y, round(heading, 3)))
    return poses


def write_route(
    folder: Path,
    points: list[tuple[float, float]] | None = None,
    fixed_heading_deg: float | None = None,
    lost: Mapping[int, Sequence[str]] | None = None,
    timestamps_ms: Sequence[float] | None = None,
) -> Path:
    """A route database through ``points`` (mm; default :func:`arc_points`) in ``folder``:
    BoB's route file names, no grid columns; ``folder``. ``fixed_heading_deg``: every image
    taken at that compass heading instead (a camera that does not turn with the robot).
    ``lost``: row k lost the values named (of X, Y, Heading), its image taken where it
    belongs; ``timestamps_ms``: each row's ``Timestamp [ms]``, a column after the rest."""
    folder.mkdir(parents=True, exist_ok=True)
    time = ", Timestamp [ms]" if timestamps_ms is not None else ""
    lines = [f"X [mm], Y [mm], Z [mm], Heading [degrees], Filename{time}"]
    for k, (x, y, heading) in enumerate(route_poses(points)):
        heading = heading if fixed_heading_deg is None else fixed_heading_deg
        name = f"image{k + 1:05d}.png"
        _write_image(folder / name, x, y, heading, colour=False)
        pose = _cells({"X": x, "Y": y, "Heading": heading}, (lost or {}).get(k, ()))
        stamp = f", {timestamps_ms[k]:g}" if timestamps_ms is not None else ""
        lines.append(f"{pose}, {name}{stamp}")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (folder / "database_metadata.yaml").write_text(ROUTE_METADATA)
    return folder
