"""Office and lab furniture built from prisms: rows of identical units against a wall, desks with
screens, open shelving, benches, potted plants and a wall-mounted fire extinguisher.

The floor makers have the :data:`~homebench.data.synth.layout.Maker` signature ``(rng, planner,
k) -> list[Prism]`` (extra keywords bound with ``functools.partial``) and return [] when the
planner finds no room. The units of one row share their textures (identical cabinets, lockers,
desks, screens): the repeated structures of real offices. Sizes are metres.
"""

from __future__ import annotations

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.layout import (
    FloorPlanner,
    WallSpot,
    potted_plant,
)
from homebench.data.synth.scene import Box, Cylinder, Prism, texture_shape
from homebench.data.synth.walls import (
    Fixture,
    WallCanvas,
    WallPlanner,
    px,
)

Rng = np.random.Generator
ALL_WALLS = (0, 1, 2, 3)


def _at(spot: WallSpot, lx: float, ly: float) -> tuple[float, float]:
    """World (x, y) of a point at (lx, ly) in the frame of ``spot`` (local -y: into the room)."""
    ca, sa = np.cos(spot.angle), np.sin(spot.angle)
    return float(spot.x + lx * ca - ly * sa), float(spot.y + lx * sa + ly * ca)


def _box(
    name: str,
    spot: WallSpot,
    local: tuple[float, float],
    size: tuple[float, float],
    z: tuple[float, float],
    side: tx.Texture,
    cap: tx.Texture,
) -> Box:
    """A box of ``size`` over ``z`` at ``local`` (lx, ly) in the frame of ``spot``, turned
    like it."""
    return Box(name, *z, side, cap, centre=_at(spot, *local), size=size, angle=spot.angle)


def _row(n: int, width: float) -> list[float]:
    """Local x of the centres of ``n`` units of ``width`` side by side, centred on 0."""
    return [(i + 0.5 - n / 2) * width for i in range(n)]


def cabinet_row(
    rng: Rng, planner: FloorPlanner, k: int, walls: tuple[int, ...] = ALL_WALLS
) -> list[Prism]:
    """2-4 identical steel cabinets (double doors, 0.8-1.0 wide) or locker units (three narrow
    vented doors each) side by side, 1.8-2.0 high, against one of ``walls``."""
    lockers = bool(rng.random() < 0.4)
    sx, sy = float(rng.uniform(0.8, 1.0)), float(rng.uniform(0.42, 0.5))
    height, n = float(rng.uniform(1.8, 2.0)), int(rng.integers(2, 5))
    spot = planner.against_wall(n * sx, sy, walls)
    if spot is None:
        return []
    shape = texture_shape(2 * (sx + sy), height)
    side = tx.cabinet_front(rng, shape, px(sx), 3 if lockers else 2, lockers)
    cap = tx.metal(rng, texture_shape(sx, sy))
    name = f"{'lockers' if lockers else 'cabinets'}_{k}"
    return [
        _box(f"{name}/unit_{i}", spot, (x, 0.0), (sx, sy), (0.0, height), side, cap)
        for i, x in enumerate(_row(n, sx))
    ]


def shelving(
    rng: Rng, planner: FloorPlanner, k: int, walls: tuple[int, ...] = ALL_WALLS
) -> list[Prism]:
    """1-2 open steel shelving units side by side against one of ``walls``, 1.8-2.2 high, full
    of rows of identical binders and archive boxes (:func:`~textures.binders`)."""
    n, sx, sy = int(rng.integers(1, 3)), float(rng.uniform(0.9, 1.2)), 0.4
    height = float(rng.uniform(1.8, 2.2))
    spot = planner.against_wall(n * sx, sy, walls)
    if spot is None:
        return []
    shape = texture_shape(2 * (sx + sy), height)
    cap = tx.metal(rng, texture_shape(sx, sy))
    out: list[Prism] = []
    for i, x in enumerate(_row(n, sx)):
        side = tx.metal(rng, shape)
        side[:, : px(sx)] = tx.binders(rng, (shape[0], px(sx)), px(0.03))
        out.append(
            _box(f"shelving_{k}/unit_{i}", spot, (x, 0.0), (sx, sy), (0.0, height), side, cap)
        )
    return out


def desk_row(
    rng: Rng, planner: FloorPlanner, k: int, walls: tuple[int, ...] = ALL_WALLS
) -> list[Prism]:
    """One or two identical desks side by side against one of ``walls``: one top 0.72 m high on
    side panels (shared between neighbours, as in desk systems); on each desk one or two
    switched-off screens of one model on stands and a keyboard, under half of them a computer.
    Office chairs are not included (they are the ``chairs`` variant)."""
    n = int(rng.integers(1, 3))
    length, depth = float(rng.uniform(1.4, 1.8)), float(rng.uniform(0.7, 0.8))
    spot = planner.against_wall(n * length, depth, walls)
    if spot is None:
        return []
    top, row = (0.72, 0.75), (n * length, depth)
    material = tx.wood if rng.random() < 0.5 else tx.metal
    desk_side = material(rng, texture_shape(2 * sum(row), top[1] - top[0]))
    name = f"desks_{k}"
    out: list[Prism] = [
        _box(
            f"{name}/top", spot, (0.0, 0.0), row, top, desk_side, material(rng, texture_shape(*row))
        )
    ]
    panel = (0.03, depth - 0.04)
    panel_side = tx.metal(rng, texture_shape(2 * sum(panel), top[0]))
    panel_cap = tx.blank(texture_shape(*panel), 0.3)
    for i in range(n + 1):
        at = (float(np.clip((i - n / 2) * length, -row[0] / 2 + 0.015, row[0] / 2 - 0.015)), 0.0)
        out.append(_box(f"{name}/panel_{i}", spot, at, panel, (0.0, top[0]), panel_side, panel_cap))
    screen, screen_z = (float(rng.uniform(0.5, 0.6)), 0.05), (0.86, 0.86 + 0.34)
    screen_side = tx.monitor(rng, texture_shape(2 * sum(screen), 0.34), px(screen[0]))
    dark = tx.blank(texture_shape(0.1, 0.1), 0.12)
    keys = (0.45, 0.15)
    keys_side = tx.blank(texture_shape(2 * sum(keys), 0.03), 0.2)
    keys_cap = tx.checker(texture_shape(*keys), (5, 18), 0.15, 0.3)
    tower = (0.2, 0.45)
    tower_side = tx.cabinet_front(rng, texture_shape(2 * sum(tower), 0.45), px(tower[0]), 1, True)
    for i, x in enumerate(_row(n, length)):
        desk = f"{name}/desk_{i}"
        for j, sx in enumerate(_row(int(rng.integers(1, 3)), screen[0] + 0.05)):
            ly = depth / 2 - 0.25
            parts = (
                ("screen", (x + sx, ly), screen, screen_z, screen_side),
                ("stand", (x + sx, ly + 0.04), (0.06, 0.06), (top[1], screen_z[0]), dark),
            )
            for what, at, size, z, side in parts:
                out.append(_box(f"{desk}/{what}_{j}", spot, at, size, z, side, dark))
        at = (x, -depth / 2 + 0.2)
        out.append(
            _box(f"{desk}/keyboard", spot, at, keys, (top[1], top[1] + 0.03), keys_side, keys_cap)
        )
        if rng.random() < 0.5:
            at = (x + length / 2 - 0.2, 0.0)
            out.append(_box(f"{desk}/computer", spot, at, tower, (0.0, 0.45), tower_side, dark))
    return out


def bench(
    rng: Rng, planner: FloorPlanner, k: int, walls: tuple[int, ...] = ALL_WALLS
) -> list[Prism]:
    """A bench 1.2-1.8 long against one of ``walls``: a wooden seat on two steel side frames."""
    length, depth, seat = float(rng.uniform(1.2, 1.8)), 0.4, float(rng.uniform(0.43, 0.47))
    spot = planner.against_wall(length, depth, walls)
    if spot is None:
        return []
    wood = tx.wood(rng, texture_shape(2 * (length + depth), 0.05))
    out: list[Prism] = [
        _box(
            f"bench_{k}/seat",
            spot,
            (0.0, 0.0),
            (length, depth),
            (seat, seat + 0.05),
            wood,
            tx.wood(rng, texture_shape(length, depth)),
        )
    ]
    frame = (0.05, depth - 0.04)
    steel = tx.metal(rng, texture_shape(2 * sum(frame), seat)) * 0.5
    cap = tx.blank(texture_shape(*frame), 0.2)
    for side in (-1, 1):
        at = (side * (length / 2 - 0.1), 0.0)
        out.append(_box(f"bench_{k}/frame_{side}", spot, at, frame, (0.0, seat), steel, cap))
    return out


def wall_plant(
    rng: Rng, planner: FloorPlanner, k: int, walls: tuple[int, ...] = ALL_WALLS
) -> list[Prism]:
    """A potted plant 1.2-1.8 high standing against one of ``walls``, within a 0.8 m square."""
    half = 0.4
    spot = planner.against_wall(2 * half, 2 * half, walls)
    if spot is None:
        return []
    centre = (spot.x, spot.y)

    def inside(parts: list[Prism]) -> bool:
        return all(float(np.hypot(*(p.outline() - centre).T).max()) <= half for p in parts)

    pot = (float(rng.uniform(0.12, 0.18)), float(rng.uniform(0.3, 0.45)))
    return potted_plant(rng, f"pot_plant_{k}", centre, pot, float(rng.uniform(1.2, 1.8)), inside)


def fire_extinguisher(
    rng: Rng,
    walls: WallPlanner,
    floor: FloorPlanner,
    canvas: WallCanvas,
    k: int,
    choices: tuple[int, ...] = ALL_WALLS,
) -> list[Prism]:
    """A fire extinguisher hanging on one of ``choices`` (0.55-1.1 m up, clear of the grid like
    any floor object) with its square sign painted above it."""
    spots: list[WallSpot] = []

    def reserve(f: Fixture) -> bool:
        spot = floor.at_wall(f.wall, sum(f.along) / 2, 0.2, 0.2, gap=0.01)
        if spot is not None:
            spots.append(spot)
        return spot is not None

    f = walls.place(0.3, (0.5, 1.75), choices, accept=reserve)
    if f is None:
        return []
    mid = sum(f.along) / 2
    sign = Fixture(f.wall, (mid - 0.1, mid + 0.1), (1.5, 1.7))
    canvas.paint(sign, lambda s: tx.safety_sign(s, "extinguisher"))
    x, y = spots[-1].x, spots[-1].y
    radius = 0.08
    body = tx.extinguisher(rng, texture_shape(2 * np.pi * radius, 0.55))
    black = tx.blank(texture_shape(0.1, 0.1), 0.08)
    return [
        Cylinder(f"extinguisher_{k}/body", 0.55, 1.1, body, black, centre=(x, y), radius=radius),
        Cylinder(
            f"extinguisher_{k}/valve",
            1.1,
            1.2,
            tx.blank(texture_shape(0.2, 0.1), 0.15),
            black,
            centre=(x, y),
            radius=0.03,
        ),
    ]
