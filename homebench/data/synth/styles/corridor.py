"""The corridor (style ``corridor``): an office corridor 3.6 m wide, 16 m long and 2.7 m high.

Both long walls have flush office doors at one regular pitch (2.5, 3 or 3.75 m, the office
module), facing each other or staggered; the doors look alike (one leaf and frame colour), only
their room signs' numbers and names differ, a few have a glass vision panel, and a slot here and
there has no door. A protection rail runs along both walls at hip height; some corridors have
a darker dado. A few radiators, one to three notice boards, perhaps a poster, a wall-mounted
fire extinguisher with its sign. One end wall has a window or a full-height glazed door with a
venetian blind; the other a double fire door to the stairwell with vision panels and an exit
sign above it. A single row of identical luminaires along the tiled ceiling; a floor of regular
tiles. Few objects, all in the corridor's ends beyond the capture grid: benches, bins, potted
plants. Long, narrow and repetitive: the doors at a regular pitch look alike from afar.

Variants:

- ``original``: the luminaires on, the end window's blind down and shut; the offices behind the
  vision panels unlit (evening).
- ``arboreal`` / ``chairs``: the same, with a tall potted plant / 2-4 chairs in the grid.
- ``day``: the blind raised: daylight through the end window with sun patches on the floor
  near it; daylit offices seen through the vision panels and the stairwell door; the
  luminaires still on.
- ``twilight``: luminaires off, only the dim light of dusk through the end window: the camera
  needs about 30 x ``original``'s exposure (its longest time and a gain of about 5, hence
  much more noise).
- ``winlit``: luminaires off, lit only through the end window, the vision panels and the
  stairwell door: bright at the window end, dim at the other.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.furniture import bench, fire_extinguisher, wall_plant
from homebench.data.synth.layout import (
    FloorPlanner,
    Maker,
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
)
from homebench.geometry import Grid

#: Light of each variant (intensities in the lighting model's units, see ``lighting.py``). The
#: ambient (inter-reflected) light of the daylight-only variants is about half the poster
#: room's: one end window lights 220 m^2 of walls, floor and ceiling.
LIGHTINGS: dict[Variant, Lighting] = indoor_lightings(
    day=Lighting(130.0, 230.0, 2200.0, 1100.0, 600.0, 1500.0, True),
    twilight=Lighting(4.0, 0.0, 30.0, 0.0, 0.0, 25.0, True),
    winlit=Lighting(30.0, 0.0, 800.0, 0.0, 0.0, 700.0, True),
)
#: Pitches of the doors along the corridor (office modules of 1.25 m: 2, 2.4 or 3 modules), m.
DOOR_PITCHES = (2.5, 3.0, 3.75)


def _walls_paint(
    rng: np.random.Generator, room: Room, canvas: WallCanvas, long_walls: tuple[int, ...]
) -> None:
    """A darker dado in half the corridors, skirting, and a protection rail on the long walls;
    doors and boards are painted over them."""
    if rng.random() < 0.5:
        top, paint = float(rng.uniform(1.0, 1.3)), float(rng.uniform(0.4, 0.55))
        for wall in range(4):
            dado = Fixture(wall, (0.0, room.wall_length(wall)), (0.0, top))
            canvas.paint(dado, lambda s: tx.plain_wall(rng, s, (paint, paint)))
    canvas.skirting()
    z, grey = float(rng.uniform(0.85, 0.95)), float(rng.uniform(0.3, 0.6))
    for wall in long_walls:
        canvas.band(wall, (z, z + 0.1), grey)
        canvas.band(wall, (z + 0.09, z + 0.1), min(grey + 0.2, 0.9))


def _office_doors(
    rng: np.random.Generator,
    room: Room,
    canvas: WallCanvas,
    walls: WallPlanner,
    floor: FloorPlanner,
    long_walls: tuple[int, ...],
) -> None:
    """Doors at one regular pitch along both long walls, facing or staggered; 15 % of the slots
    have none (never two in a row: a room spans at most two slots). Room numbers run along the
    corridor, odd on one side, even on the other."""
    look = (float(rng.uniform(0.35, 0.75)), float(rng.choice([0.15, 0.3, 0.85])))
    pitch = float(rng.choice(DOOR_PITCHES))
    start = float(rng.uniform(0.4, 0.4 + pitch))
    shift = 0.0 if rng.random() < 0.5 else pitch / 2
    storey = int(rng.integers(0, 4))
    for side, wall in enumerate(long_walls):
        length = room.wall_length(wall)
        reverse = wall in (0, 3)  # these walls unroll against the corridor's axis
        skipped = False
        for k, p in enumerate(np.arange(start + side * shift, length - DOOR_SPAN - 0.3, pitch)):
            skipped = not skipped and bool(rng.random() < 0.15)
            if skipped:
                continue
            a = length - p - DOOR_SPAN if reverse else p
            f = Fixture(wall, (float(a), float(a) + DOOR_SPAN), (0.0, DOOR_HEIGHT))
            walls.placed.append(f)
            vision = bool(rng.random() < 0.3)
            office_door(rng, canvas, f, look, vision, f"{storey}.{101 + 2 * k + side:03d}")
            floor.keep_clear(f, 0.9)


def _stairwell(
    rng: np.random.Generator,
    room: Room,
    canvas: WallCanvas,
    walls: WallPlanner,
    floor: FloorPlanner,
    wall: int,
) -> None:
    """A double fire door to the stairwell centred on ``wall``, glazed (the daylit stairwell
    shows through) and with an exit sign above it."""
    width = float(rng.uniform(1.5, 1.9))
    ((a0, a1),) = bays(room.wall_length(wall), 1, width)
    door = Fixture(wall, (a0, a1), (0.0, 2.2))
    walls.placed.append(door)
    leaf, frame_grey = float(rng.uniform(0.4, 0.8)), float(rng.uniform(0.2, 0.5))
    rows, cols = canvas.shape(door)
    glazing = (tx.GLAZED_PANEL, (0.2, 0.35))  # the stairwell has large windows
    right = tx.office_door(rng, (rows, cols - cols // 2), leaf, frame_grey, *glazing)
    left = tx.office_door(rng, (rows, cols // 2), leaf, frame_grey, *glazing)
    albedo, glow = (np.hstack([a[:, ::-1], b]) for a, b in zip(left, right, strict=True))
    canvas.put(door, albedo, glow=glow)
    mid = (a0 + a1) / 2
    sign = Fixture(wall, (mid - 0.2, mid + 0.2), (2.3, 2.5))
    walls.placed.append(sign)
    canvas.paint(sign, lambda s: tx.safety_sign(s, "exit"))
    floor.keep_clear(door, 1.2)


def _end_window(
    rng: np.random.Generator, room: Room, canvas: WallCanvas, walls: WallPlanner, wall: int
) -> list[Window]:
    """A window (sill 0.9 m, 1.2-2 m wide) or a full-height glazed door (1-1.4 m wide) with a
    venetian blind, centred on ``wall``."""
    if rng.random() < 0.6:
        width, z = float(rng.uniform(1.2, 2.0)), (0.9, min(2.3, room.height - 0.2))
    else:
        width, z = float(rng.uniform(1.0, 1.4)), (0.02, min(2.3, room.height - 0.2))
    return blind_windows(rng, canvas, walls, wall, bays(room.wall_length(wall), 1, width), z)


def _wall_items(
    rng: np.random.Generator, canvas: WallCanvas, walls: WallPlanner, long_walls: tuple[int, ...]
) -> None:
    """1-3 radiators, 1-3 notice boards and perhaps a poster between the doors."""
    plan: Plan = []
    plan += [
        ((0.8, 1.2), (0.15, 0.7), lambda s: tx.radiator(rng, s))
        for _ in range(int(rng.integers(1, 4)))
    ]
    plan += [
        ((0.7, 1.2), (1.0, 1.8), lambda s: tx.notice_board(rng, s))
        for _ in range(int(rng.integers(1, 4)))
    ]
    if rng.random() < 0.5:
        plan.append(((0.5, 0.7), (1.2, 1.9), lambda s: tx.poster(rng, s)))
    hang(rng, canvas, walls, plan, long_walls)


def build(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded corridor without any variant additions; its long axis is the room's longer."""
    rng = np.random.default_rng([seed, 0])
    floor = floor_planner(rng, room, grid)
    walls = WallPlanner(rng, room)
    along_y = room.depth >= room.width
    long_walls, ends = ((1, 3), (0, 2)) if along_y else ((0, 2), (1, 3))
    shape = texture_shape(room.perimeter, room.height)
    canvas = WallCanvas.plain(room, tx.plain_wall(rng, shape, (0.65, 0.85)))
    _walls_paint(rng, room, canvas, long_walls)
    window_end = int(rng.choice(ends))
    windows = _end_window(rng, room, canvas, walls, window_end)
    _stairwell(rng, room, canvas, walls, floor, sum(ends) - window_end)
    _office_doors(rng, room, canvas, walls, floor, long_walls)
    _wall_items(rng, canvas, walls, long_walls)
    objects = fire_extinguisher(rng, walls, floor, canvas, 0, long_walls)
    tile = int(TEXELS_PER_METRE * float(rng.choice([0.3, 0.4, 0.5, 0.6])))
    shade = float(rng.uniform(0.2, 0.45))
    alternate = 0.12 if rng.random() < 0.3 else 0.0
    floor_surface = room.floor(
        tx.tiles(
            rng,
            texture_shape(room.width, room.depth),
            tile,
            (shade - 0.03, shade + 0.03),
            alternate,
        )
    )
    across = min(room.width, room.depth)
    pitch = float(rng.uniform(2.2, 3.0))
    size = (0.3, 1.25) if rng.random() < 0.6 else (0.625, 0.625)
    louvres = int(rng.integers(0, 10))
    lights = LightGrid(
        (across, pitch) if along_y else (pitch, across),
        size if along_y else size[::-1],
        louvres,
    )
    ceiling_surface, bars = ceiling(rng, room, lights, tile=0.625)
    makers: list[tuple[Maker, tuple[int, int]]] = [
        (bench, (0, 3)),
        (partial(waste_bin, walls=long_walls), (1, 3)),
        (partial(wall_plant, walls=long_walls), (0, 3)),
    ]
    objects += furnish(rng, floor, makers)
    return Scene(room, canvas.surface(), floor_surface, ceiling_surface, objects, windows, bars)
