"""Brains on Board image databases written by hand, as BoB robotics' recorders leave them.

The images are panoramas of the analytic arena (tests/synthetic_panorama.py: 288 x 48, +-30
deg, azimuth 0 at column 0 growing ccw), rendered at each pose with its own heading and
written with cv2; the CSV and the metadata are typed text: spaces after the commas, positions
in mm, headings in degrees and not all equal, OpenCV's ``%YAML:1.0`` line and a
``!!opencv-matrix``. No homebench code writes any of it, so a reading bug of homebench's
cannot cancel out.

The arena images match what homebench assumes of unwrapped BoB images (the horizon at the
middle row, square pixels, azimuth 0 at column 0 growing to the right), so that ``data check``
must agree with them without a ``homebench.yaml``.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
from synthetic_panorama import GEOMETRY, render

from homebench.geometry import Pose

GRID_SHAPE = (5, 5)
SPACING_MM = 300.0
ORIGIN_MM = (-600.0, -450.0)
Z_MM = 10.0
HEADING_DEG = 30.0
#: Images taken at another heading than the rest.
TURNED_DEG = {(1, 2): 75.0, (3, 3): -20.0, (4, 0): 200.0}
#: The route: poses on an arc around the arena centre, each facing along it.
ROUTE_POSES = 10

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
      resolution: [ 288, 48 ]
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
      resolution: [ 288, 48 ]
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
    image = render(Pose(x_mm / 1000.0, y_mm / 1000.0, math.radians(heading_deg))).image
    if colour:  # a recorder's colour image: homebench reads it as grey
        image = np.repeat(image[:, :, None], 3, axis=2)
    assert cv2.imwrite(str(path), image)


def write_grid(folder: Path) -> Path:
    """A 5 x 5 grid database in ``folder``, rows in no grid order, a pitch, a roll and a
    timestamp column among the standard ones; ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    lines = [
        "X [mm], Y [mm], Z [mm], Heading [degrees], Pitch [degrees], Roll [degrees], "
        "Filename, Grid X, Grid Y, Grid Z, Timestamp [ms]"
    ]
    cells = [(i, j) for j in range(GRID_SHAPE[1]) for i in range(GRID_SHAPE[0])]
    order = np.random.default_rng(7).permutation(len(cells))
    for n, k in enumerate(order):
        i, j = cells[k]
        x, y = grid_position_mm(i, j)
        heading = grid_heading_deg(i, j)
        name = grid_name(x, y)
        _write_image(folder / name, x, y, heading, colour=(i, j) == (2, 2))
        lines.append(f"{x:g}, {y:g}, {Z_MM:g}, {heading:g}, nan, 0, {name}, {i}, {j}, 0, {n * 40}")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (folder / "database_metadata.yaml").write_text(GRID_METADATA)
    return folder


def route_poses() -> list[tuple[float, float, float]]:
    """(x mm, y mm, heading deg) of the route: an arc of radius 1 m, 0 to 90 deg."""
    poses = []
    for k in range(ROUTE_POSES):
        angle = math.radians(90.0 * k / (ROUTE_POSES - 1))
        x, y = 1000.0 * math.cos(angle), 1000.0 * math.sin(angle)
        poses.append((round(x, 2), round(y, 2), round(math.degrees(angle) + 90.0, 3)))
    return poses


def write_route(folder: Path) -> Path:
    """A route database in ``folder``: BoB's route file names, no grid columns; ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    lines = ["X [mm], Y [mm], Z [mm], Heading [degrees], Filename"]
    for k, (x, y, heading) in enumerate(route_poses()):
        name = f"image{k + 1:05d}.png"
        _write_image(folder / name, x, y, heading, colour=False)
        lines.append(f"{x:g}, {y:g}, {Z_MM:g}, {heading:g}, {name}")
    (folder / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (folder / "database_metadata.yaml").write_text(ROUTE_METADATA)
    return folder


#: The arena's camera model, which homebench must assume for these folders.
ARENA = GEOMETRY
