"""The lab (style ``lab``): a robotics lab of 6.6 x 9 m, 3 m high, like the Bielefeld one the
grid databases were taken in.

Plain painted walls. One long wall is a facade of 2-4 identical windows in regular bays, each
with a venetian blind and a radiator under it. A few large dark and bright regions: a
blackboard or a floor-to-ceiling blackout curtain, a large whiteboard, the windows. One or two
flush doors with room signs; white cable trunking with sockets at a regular pitch; a cable tray
along the top of a wall; at most two pictures (posters or a notice board), maybe a clock; a
fire extinguisher. A tiled ceiling with a grid of identical louvred luminaires; a sheet
linoleum floor. Against the walls around the capture grid: rows of identical steel cabinets
or lockers, rows of identical desks with switched-off screens, open shelving full of identical
binders, a bin or two. Office chairs are not in the base (they are the ``chairs`` variant).
Much repeated structure and few distinctive textures: a harder place for feature methods than
the poster room.

Variants:

- ``original``: an evening in the lab: blinds down and shut, the luminaires on.
- ``arboreal`` / ``chairs``: the same, with a tall potted plant / 2-4 office chairs in the grid.
- ``day``: blinds raised (some lowered with their slats open): daylight through every window,
  sun patches on the floor and walls, the luminaires still on.
- ``twilight``: luminaires off, blinds open, only the dim light of dusk through the windows:
  the camera needs about 15 x ``original``'s exposure (its longest time and a gain of about 2,
  hence more noise), as in the poster room.
- ``winlit``: luminaires off, blinds open, lit only by an overcast day through the windows.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.furniture import (
    cabinet_row,
    desk_row,
    fire_extinguisher,
    shelving,
)
from homebench.data.synth.layout import (
    FloorPlanner,
    Maker,
    box_stack,
    floor_planner,
    furnish,
    waste_bin,
)
from homebench.data.synth.lighting import Lighting, indoor_lightings
from homebench.data.synth.scene import TEXELS_PER_METRE, Room, Scene, Window, texture_shape
from homebench.data.synth.spec import Variant
from homebench.data.synth.walls import (
    DOOR_HEIGHT,
    DOOR_SPAN,
    Fixture,
    LightGrid,
    Plan,
    WallCanvas,
    WallPlanner,
    bays,
    blind_windows,
    ceiling,
    hang,
    office_door,
    px,
)
from homebench.geometry import Grid

#: Light of each variant (intensities in the lighting model's units, see ``lighting.py``). The
#: luminaires are the poster room's; each of the 2-4 windows gives less diffuse daylight than
#: each of the poster room's 1-2, for about the same daylight in all.
LIGHTINGS: dict[Variant, Lighting] = indoor_lightings(
    day=Lighting(130.0, 230.0, 1600.0, 1100.0, 600.0, 1500.0, True),
    twilight=Lighting(8.0, 0.0, 25.0, 0.0, 0.0, 25.0, True),
    winlit=Lighting(60.0, 0.0, 600.0, 0.0, 0.0, 700.0, True),
)


def _facade(
    rng: np.random.Generator, room: Room, canvas: WallCanvas, walls: WallPlanner
) -> list[Window]:
    """2-4 identical windows with blinds in regular bays along one of the long walls."""
    wall = int(rng.choice((1, 3) if room.depth >= room.width else (0, 2)))
    n = int(rng.integers(2, 5))
    length = room.wall_length(wall)
    width = float(rng.uniform(0.55, 0.8)) * length / n
    z = (0.85, min(float(rng.uniform(2.4, 2.6)), room.height - 0.25))
    return blind_windows(rng, canvas, walls, wall, bays(length, n, width), z)


def _services(
    rng: np.random.Generator, room: Room, canvas: WallCanvas, inner: tuple[int, ...]
) -> None:
    """Skirting; white trunking with sockets at a regular pitch round the inner walls; a cable
    tray along the top of the wall facing the windows. Doors and boards are painted over them."""
    canvas.skirting()
    z = float(rng.uniform(0.95, 1.1))
    pitch, offset = px(float(rng.uniform(1.2, 1.8))), px(float(rng.uniform(0.3, 1.0)))
    for wall in inner:
        duct = Fixture(wall, (0.0, room.wall_length(wall)), (z, z + 0.08))
        canvas.paint(duct, lambda s: tx.cable_duct(s, pitch, px(0.07), offset))
    facing = inner[1]
    tray = Fixture(facing, (0.0, room.wall_length(facing)), (room.height - 0.3, room.height - 0.1))
    canvas.paint(tray, lambda s: tx.pipes(rng, s))


def _doors(
    rng: np.random.Generator,
    canvas: WallCanvas,
    walls: WallPlanner,
    floor: FloorPlanner,
    inner: tuple[int, ...],
) -> None:
    """One or two flush doors of one look with room signs; their swing is kept free."""
    look = (float(rng.uniform(0.35, 0.75)), float(rng.choice([0.15, 0.3, 0.85])))
    storey = int(rng.integers(0, 4))
    for k in range(int(rng.integers(1, 3))):
        f = walls.place(DOOR_SPAN, (0.0, DOOR_HEIGHT), inner)
        if f is not None:
            vision = bool(rng.random() < 0.3)
            office_door(rng, canvas, f, look, vision, f"{storey}.{104 + 2 * k:03d}")
            floor.keep_clear(f, 0.9)


def _boards(
    rng: np.random.Generator,
    room: Room,
    canvas: WallCanvas,
    walls: WallPlanner,
    floor: FloorPlanner,
    inner: tuple[int, ...],
) -> None:
    """The large dark region (a blackboard or a floor-to-ceiling blackout curtain) and a large
    whiteboard, with the floor in front of them kept free; at most two pictures (posters or
    notice boards) and maybe a clock."""
    large: Plan = []
    if rng.random() < 0.5:
        curtain = (0.1, room.height - 0.35)
        large.append(
            ((1.5, 2.8), curtain, lambda s: tx.curtains_closed(rng, s, (0.06, 0.14), 0.25))
        )
    else:
        large.append(((1.5, 2.4), (0.8, 2.0), lambda s: tx.blackboard(rng, s)))
    large.append(((1.8, 2.6), (0.9, 2.1), lambda s: tx.whiteboard(rng, s)))
    for f in hang(rng, canvas, walls, large, inner):
        floor.keep_clear(f, 0.9)
    small: Plan = []
    for _ in range(int(rng.integers(0, 3))):
        if rng.random() < 0.5:
            small.append(((0.5, 0.8), (1.2, 1.9), lambda s: tx.poster(rng, s)))
        else:
            small.append(((0.8, 1.2), (1.1, 1.8), lambda s: tx.notice_board(rng, s)))
    if rng.random() < 0.5:
        small.append(((0.3, 0.3), (2.2, 2.5), lambda s: tx.clock(rng, s[0])))
    hang(rng, canvas, walls, small, inner)


def build(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded lab without any variant additions."""
    rng = np.random.default_rng([seed, 0])
    floor = floor_planner(rng, room, grid)
    walls = WallPlanner(rng, room)
    shape = texture_shape(room.perimeter, room.height)
    canvas = WallCanvas.plain(room, tx.plain_wall(rng, shape, (0.7, 0.85)))
    windows = _facade(rng, room, canvas, walls)
    window_wall = windows[0].wall
    inner = tuple((window_wall + k) % 4 for k in (1, 2, 3))  # inner[1] faces the windows
    _services(rng, room, canvas, inner)
    _doors(rng, canvas, walls, floor, inner)
    _boards(rng, room, canvas, walls, floor, inner)
    objects = fire_extinguisher(rng, walls, floor, canvas, 0, inner)
    floor_surface = room.floor(
        tx.linoleum(rng, texture_shape(room.width, room.depth), TEXELS_PER_METRE)
    )
    size = (0.3, 1.25) if window_wall % 2 == 1 else (1.25, 0.3)  # along the windows
    pitch = (float(rng.uniform(1.9, 2.4)), float(rng.uniform(2.1, 2.6)))
    lights = LightGrid(pitch, size, int(rng.integers(6, 12)))
    ceiling_surface, bars = ceiling(rng, room, lights, tile=0.625)
    makers: list[tuple[Maker, tuple[int, int]]] = [
        (partial(cabinet_row, walls=inner), (1, 3)),
        (partial(shelving, walls=inner), (1, 3)),
        (desk_row, (2, 4)),
        (box_stack, (0, 2)),
        (waste_bin, (1, 3)),
    ]
    objects += furnish(rng, floor, makers)
    return Scene(room, canvas.surface(), floor_surface, ceiling_surface, objects, windows, bars)
