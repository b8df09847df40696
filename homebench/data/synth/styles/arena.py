"""The landmark arena (style ``arena``): the scene of the landmark-homing papers (Cartwright and
Collett 1983; Lambrinos et al. 2000; Möller 2001), a few black cylinders on a bright background,
in a plain room of 7 x 9 m, 3 m high.

Plain, bright painted walls (a skirting board, nothing else at eye level), one or two high
curtained windows well above the camera's horizon, a linoleum floor and a ceiling
with only four luminaires, so that the walls are lit unevenly, as real lamps light a room:
bright under a lamp, dimmer in the corners. The landmark array: four matt black cylinders
(radius 0.1-0.2 m, 1.8-2.4 m tall, reaching well above the camera) round the capture grid,
one in each quarter of bearing from its centre, their surface 0.5-2 m outside it, placed so
that the grid lies within the array. Nothing else stands in the room. ALV's and the snapshot
model's validation scene (tests/test_validation_alv.py, tests/test_validation_snapshot.py):
their landmarks are black on white, as in the papers, and the uneven light is what a per-image
threshold must cope with.

Variants (the arena's lamps, the poster room's daylight): ``original`` (curtains shut, the
luminaires on), ``arboreal`` and ``chairs`` (a plant / chairs added among the grid positions,
same light), ``day`` (curtains open, daylight and sun patches through the windows, the
luminaires on), ``twilight`` (luminaires off, dim light through the open windows), ``winlit``
(luminaires off, lit only through the windows).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from homebench.data.synth import textures as tx
from homebench.data.synth.lighting import Lighting, indoor_lightings
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    Cylinder,
    Prism,
    Room,
    Scene,
    Surface,
    Window,
    texture_shape,
)
from homebench.data.synth.spec import Variant
from homebench.data.synth.styles.posters import LIGHTINGS as POSTER_LIGHTINGS
from homebench.data.synth.walls import ATTEMPTS, LightGrid, WallCanvas, WallPlanner, ceiling, px
from homebench.geometry import Grid

FloatArray = NDArray[np.float64]

#: The luminaires on, curtains shut: four strong lamps and little inter-reflected (ambient)
#: light, so that the walls' irradiance at camera height varies 2:1 between a wall under a lamp
#: and the corners (min / max 0.50; the poster room's light would give 0.91), as a few ceiling
#: lamps light a room; its mean on the walls is about the poster room's.
LAMPS_ON = Lighting(25.0, 1600.0, 0.0, 0.0, 600.0, 0.0, False)
#: Light of each variant: the poster room's daylight (one or two windows), these lamps.
LIGHTINGS: dict[Variant, Lighting] = indoor_lightings(
    day=replace(POSTER_LIGHTINGS["day"], ambient=35.0, ceiling=LAMPS_ON.ceiling),
    twilight=POSTER_LIGHTINGS["twilight"],
    winlit=POSTER_LIGHTINGS["winlit"],
    lights_on=LAMPS_ON,
)
#: Four luminaires in the 7 x 9 m room (2 x 2): the walls' light varies with the distance to them.
LAMPS = LightGrid(pitch=(3.5, 4.5))
#: The landmark array: four cylinders (three cannot surround the default 2.7 x 4.8 m grid from
#: 2 m away); their radius, height and the gap between the capture grid's bounding box and a
#: cylinder's surface, metres.
COUNT, RADIUS, HEIGHT, GAP = 4, (0.1, 0.2), (1.8, 2.4), (0.5, 2.0)
#: Albedo of the cylinders' matt black paint (the wall's is 0.75-0.9).
BLACK = 0.04
#: Least distance from a cylinder to a wall, metres.
WALL_CLEARANCE = 0.3


def _walls(rng: np.random.Generator, room: Room) -> tuple[Surface, list[Window]]:
    """Plain bright walls with a skirting board and one or two high curtained windows on one
    wall (sill 1.6 m: above the horizon band of a camera about 1 m up)."""
    canvas = WallCanvas.plain(
        room, tx.plain_wall(rng, texture_shape(room.perimeter, room.height), (0.75, 0.9))
    )
    canvas.skirting()
    planner, wall, windows = WallPlanner(rng, room), int(rng.integers(4)), []
    for _ in range(int(rng.integers(1, 3))):
        f = planner.place(float(rng.uniform(1.2, 1.8)), (1.6, room.height - 0.3), (wall,))
        if f is not None:
            windows.append(Window(f.wall, f.along, f.z))
            canvas.put(f, *tx.window(rng, canvas.shape(f), px(0.06)))
    return canvas.surface(), windows


def _cylinders(rng: np.random.Generator, room: Room, grid: Grid) -> list[Prism]:
    """The landmark array: cylinders spread round the grid, one in each equal sector of bearing
    from its centre (the sectors turned at random), drawn again until the grid lies within the
    array (inside the polygon of their centres); the last draw if none does."""
    (x0, y0), (x1, y1) = grid.position(0, 0), grid.position(*(n - 1 for n in grid.shape))
    box = (np.array([(x0 + x1) / 2, (y0 + y1) / 2]), np.array([(x1 - x0) / 2, (y1 - y0) / 2]))
    sector = 2.0 * np.pi / COUNT
    cylinders: list[Prism] = []
    for _ in range(ATTEMPTS):
        turn = float(rng.uniform(0.0, sector))
        cylinders, centres = [], []
        for k in range(COUNT):
            radius, height = float(rng.uniform(*RADIUS)), float(rng.uniform(*HEIGHT))
            xy = _spot(rng, room, box, radius, (k * sector + turn, sector))
            if xy is not None:
                side = tx.blank(texture_shape(2 * np.pi * radius, height), BLACK)
                cap = tx.blank(texture_shape(2 * radius, 2 * radius), BLACK)
                name = f"cylinder_{k}"
                cylinders.append(Cylinder(name, 0.0, height, side, cap, centre=xy, radius=radius))
                centres.append(xy)
        if len(cylinders) == COUNT and _surrounds(np.array(centres), box):
            break
    return cylinders


def _surrounds(centres: FloatArray, box: tuple[FloatArray, FloatArray]) -> bool:
    """Whether the polygon of ``centres`` (m, 2), taken in order of bearing from the box's
    centre, holds every corner of ``box`` (centre, half extents)."""
    centre, half = box
    offsets = centres - centre
    corners = centres[np.argsort(np.arctan2(offsets[:, 1], offsets[:, 0]))]
    edges = np.roll(corners, -1, axis=0) - corners
    for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        to_corner = centre + half * (sx, sy) - corners
        if np.any(edges[:, 0] * to_corner[:, 1] - edges[:, 1] * to_corner[:, 0] <= 0):
            return False
    return True


def _spot(
    rng: np.random.Generator,
    room: Room,
    box: tuple[FloatArray, FloatArray],
    radius: float,
    sector: tuple[float, float],
) -> tuple[float, float] | None:
    """A floor point (x, y) for a cylinder of ``radius`` whose bearing from the grid's box
    (centre, half extents) lies in ``sector`` (start, width; radians), its surface
    :data:`GAP` from the box and :data:`WALL_CLEARANCE` from the walls; None if rejection
    sampling finds none."""
    centre, half = box
    margin = radius + WALL_CLEARANCE
    for _ in range(ATTEMPTS):
        xy = rng.uniform((margin, margin), (room.width - margin, room.depth - margin))
        offset = xy - centre
        bearing = (np.arctan2(offset[1], offset[0]) - sector[0]) % (2.0 * np.pi)
        gap = float(np.hypot(*np.maximum(np.abs(offset) - half, 0.0))) - radius
        if bearing < sector[1] and GAP[0] <= gap <= GAP[1]:
            return float(xy[0]), float(xy[1])
    return None


def build(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded arena without any variant additions."""
    rng = np.random.default_rng([seed, 0])
    wall, windows = _walls(rng, room)
    floor = room.floor(tx.linoleum(rng, texture_shape(room.width, room.depth), TEXELS_PER_METRE))
    ceiling_surface, bars = ceiling(rng, room, LAMPS)
    objects = _cylinders(rng, room, grid)
    return Scene(room, wall, floor, ceiling_surface, objects, windows, bars)
