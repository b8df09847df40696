"""The poster room (style ``posters``): a textured office of 6 x 8.4 m full of distinctive
pictures.

Walls of painted plaster carry 14-21 posters (matplotlib's sample photographs, elevation maps,
shapes, text), doors, bookshelves, a whiteboard, notice boards, a clock and a window wall with
one or two curtained windows and radiators; pipes run along the top of every wall. Ceiling
tiles with fluorescent light bars; cabinets, tables, box stacks and bins stand around the
capture grid. Rich in unique texture: an easy place for feature methods.

Variants: ``original`` (curtains shut, light bars on), ``arboreal`` and ``chairs`` (objects
added, same light), ``day`` (curtains open, daylight and sun patches through the window),
``twilight`` (light bars off, dim light through the open window), ``winlit`` (light bars off,
lit only through the window).
"""

from __future__ import annotations

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.layout import (
    box_stack,
    cabinet,
    floor_planner,
    furnish,
    table,
    waste_bin,
)
from homebench.data.synth.lighting import Lighting, indoor_lightings
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    Room,
    Scene,
    Surface,
    Window,
    texture_shape,
)
from homebench.data.synth.spec import Variant
from homebench.data.synth.walls import (
    Fixture,
    Plan,
    WallCanvas,
    WallPlanner,
    ceiling,
    hang,
    px,
)
from homebench.geometry import Grid

#: Light of each variant (intensities in the lighting model's units, see ``lighting.py``).
LIGHTINGS: dict[Variant, Lighting] = indoor_lightings(
    day=Lighting(120.0, 230.0, 2200.0, 1100.0, 600.0, 1500.0, True),
    twilight=Lighting(8.0, 0.0, 30.0, 0.0, 0.0, 25.0, True),
    winlit=Lighting(60.0, 0.0, 800.0, 0.0, 0.0, 700.0, True),
)


def _paint_walls(rng: np.random.Generator, room: Room) -> tuple[Surface, list[Window]]:
    shape = texture_shape(room.perimeter, room.height)
    canvas = WallCanvas.plain(room, tx.plain_wall(rng, shape))
    planner = WallPlanner(rng, room)
    top = room.height - 0.25

    windows = []
    window_wall = int(rng.integers(4))
    for _ in range(2):
        f = planner.place(float(rng.uniform(1.2, 1.8)), (0.9, min(2.3, top)), (window_wall,))
        if f is None:
            continue
        windows.append(Window(f.wall, f.along, f.z))
        canvas.put(f, *tx.window(rng, canvas.shape(f), px(0.06)))
        rad = Fixture(f.wall, (f.along[0] + 0.15, f.along[1] - 0.15), (0.15, 0.7))
        planner.placed.append(rad)
        canvas.paint(rad, lambda s: tx.radiator(rng, s))

    canvas.skirting()
    doors = [w for w in range(4) if w != window_wall]
    for _ in range(int(rng.integers(1, 3))):
        f = planner.place(0.95, (0.0, min(2.05, top)), tuple(doors))
        if f is not None:
            canvas.paint(f, lambda s: tx.door(rng, s))
    plan: Plan = []  # the other fixtures, in placement order
    plan += [
        ((0.8, 1.6), (0.3, min(2.0, top)), lambda s: tx.bookshelf(rng, s, px(0.025)))
        for _ in range(int(rng.integers(1, 4)))
    ]
    plan += [((1.2, 2.0), (0.9, min(1.9, top)), lambda s: tx.whiteboard(rng, s))]
    plan += [
        ((0.6, 1.2), (1.0, min(1.8, top)), lambda s: tx.notice_board(rng, s))
        for _ in range(int(rng.integers(1, 3)))
    ]
    plan += [((0.3, 0.3), (1.95, min(2.25, top)), lambda s: tx.clock(rng, s[0]))]
    for _ in range(int(rng.integers(14, 22))):
        height = float(rng.uniform(0.4, 1.0))
        centre = float(rng.uniform(1.1, 1.9))
        z = (centre - height / 2, min(centre + height / 2, top))
        plan.append(((0.4, 1.0), z, lambda s: tx.poster(rng, s)))
    hang(rng, canvas, planner, plan)
    for wall_index in range(4):  # pipes and trays along the top of every wall
        length = room.wall_length(wall_index)
        band = float(rng.uniform(0.12, 0.25))
        pipe = Fixture(wall_index, (0.0, length), (room.height - 0.1 - band, room.height - 0.1))
        canvas.paint(pipe, lambda s: tx.pipes(rng, s))
    return canvas.surface(), windows


def build(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded poster room without any variant additions."""
    rng = np.random.default_rng([seed, 0])
    wall, windows = _paint_walls(rng, room)
    floor = room.floor(tx.floor(rng, texture_shape(room.width, room.depth), TEXELS_PER_METRE))
    ceiling_surface, bars = ceiling(rng, room)
    planner = floor_planner(rng, room, grid)
    makers = [(cabinet, (3, 7)), (table, (1, 3)), (box_stack, (3, 7)), (waste_bin, (1, 4))]
    objects = furnish(rng, planner, makers)
    return Scene(room, wall, floor, ceiling_surface, objects, windows, bars)
