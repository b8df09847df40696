"""Floor of the seeded places: the floor planner, furniture, and the variants' additions.

Walls and ceiling are :mod:`homebench.data.synth.walls`. Each style
(:mod:`homebench.data.synth.styles`) draws its base layout only from ``default_rng([seed, 0])``;
each variant's additions draw from their own stream ``default_rng([seed, 1, k])``, so adding a
plant never moves a poster. Objects stay outside the capture grid's footprint plus
:data:`GRID_MARGIN`; the variants' objects (plant, chairs) go in or next to the grid but keep
:data:`CAMERA_CLEARANCE` metres from every camera position.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.scene import Box, Cylinder, Prism, Room, Scene, texture_shape
from homebench.data.synth.walls import ATTEMPTS, Fixture, px
from homebench.errors import ConfigError
from homebench.geometry import Grid

GRID_MARGIN = 0.4
CAMERA_CLEARANCE = 0.08
_VARIANT_STREAM = {"arboreal": 1, "chairs": 2}


# --------------------------------------------------------------------------- furniture


@dataclass(frozen=True)
class WallSpot:
    """A box standing with its back to a wall: the wall (0=S, 1=W, 2=N, 3=E), ``along`` (its
    centre, metres along the wall), its centre (x, y) and the ``angle`` that turns its front
    (local -y, the first face its side texture unrolls) towards the room."""

    wall: int
    along: float
    x: float
    y: float
    angle: float


class FloorPlanner:
    """Places objects on the floor: inside the room, off each other, away from the grid.

    Footprints are kept as bounding discs (x, y, radius); ``keep_out`` is the rectangle
    (x0, y0, x1, y1) no disc may touch.
    """

    def __init__(self, rng: np.random.Generator, room: Room, keep_out: tuple[float, ...]):
        self.rng, self.room, self.keep_out = rng, room, keep_out
        self.discs: list[tuple[float, float, float]] = []

    def free(self, x: float, y: float, radius: float) -> bool:
        """Whether a disc lies inside the room, off the keep-out and off every placed disc."""
        r = self.room
        if not (radius < x < r.width - radius and radius < y < r.depth - radius):
            return False
        return self.clear(x, y, radius)

    def clear(self, x: float, y: float, radius: float) -> bool:
        """Whether a disc keeps off the keep-out rectangle and every placed disc."""
        x0, y0, x1, y1 = self.keep_out
        dx, dy = max(x0 - x, 0.0, x - x1), max(y0 - y, 0.0, y - y1)
        if np.hypot(dx, dy) < radius:
            return False
        return all(np.hypot(x - a, y - b) > radius + c for a, b, c in self.discs)

    def spot(self, radius: float) -> tuple[float, float, float] | None:
        """(x, y, angle) anywhere free for a footprint of bounding ``radius`` (for a box with
        its back to a wall: :meth:`against_wall`)."""
        for _ in range(ATTEMPTS):
            x = float(self.rng.uniform(0, self.room.width))
            y = float(self.rng.uniform(0, self.room.depth))
            angle = float(self.rng.uniform(0, np.pi))
            if self.free(x, y, radius):
                self.discs.append((x, y, radius))
                return x, y, angle
        return None

    def at_wall(
        self, wall: int, along: float, length: float, depth: float, gap: float = 0.02
    ) -> WallSpot | None:
        """Reserve a ``length`` x ``depth`` metre box ``gap`` metres in front of ``wall``,
        centred ``along`` metres into it, if it fits the wall and is clear; else None."""
        if not length / 2 + gap <= along <= self.room.wall_length(wall) - length / 2 - gap:
            return None
        spot, discs = self._box(wall, along, length, depth, gap)
        if not all(self.clear(*d) for d in discs):
            return None
        self.discs += discs
        return spot

    def keep_clear(self, f: Fixture, depth: float) -> None:
        """Reserve the floor ``depth`` metres deep in front of a wall fixture (a door's swing)
        where it is still free, so that no later object stands there."""
        _, discs = self._box(f.wall, sum(f.along) / 2, f.along[1] - f.along[0], depth, 0.0)
        self.discs += [d for d in discs if self.clear(*d)]

    def _box(
        self, wall: int, along: float, length: float, depth: float, gap: float
    ) -> tuple[WallSpot, list[tuple[float, float, float]]]:
        """The spot of a box in front of a wall and the discs that cover its footprint."""
        x, y, nx, ny = (float(a) for a in self.room.wall_xy(self.room.wall_u(wall, along)))
        x, y = x + nx * (depth / 2 + gap), y + ny * (depth / 2 + gap)
        n = int(np.ceil(length / depth))  # n discs along the wall
        radius = float(np.hypot(length / n, depth)) / 2
        offsets = (np.arange(n) + 0.5 - n / 2) * length / n
        discs = [(x - ny * t, y + nx * t, radius) for t in offsets]
        return WallSpot(wall, along, x, y, float(np.arctan2(nx, -ny))), discs

    def against_wall(
        self, length: float, depth: float, walls: tuple[int, ...] = (0, 1, 2, 3)
    ) -> WallSpot | None:
        """A random clear spot for a ``length`` x ``depth`` box with its back to one of
        ``walls`` (reserved), or None."""
        for _ in range(ATTEMPTS):
            wall = int(self.rng.choice(walls))
            along = float(self.rng.uniform(0.0, self.room.wall_length(wall)))
            spot = self.at_wall(wall, along, length, depth)
            if spot is not None:
                return spot
        return None


def floor_planner(rng: np.random.Generator, room: Room, grid: Grid) -> FloorPlanner:
    """A floor planner that keeps objects :data:`GRID_MARGIN` metres off the capture grid."""
    (gx0, gy0), (gx1, gy1) = grid.position(0, 0), grid.position(*(n - 1 for n in grid.shape))
    keep_out = (gx0 - GRID_MARGIN, gy0 - GRID_MARGIN, gx1 + GRID_MARGIN, gy1 + GRID_MARGIN)
    return FloorPlanner(rng, room, keep_out)


Maker = Callable[[np.random.Generator, FloorPlanner, int], list[Prism]]


def furnish(
    rng: np.random.Generator, planner: FloorPlanner, makers: list[tuple[Maker, tuple[int, int]]]
) -> list[Prism]:
    """Objects from each ``(maker, (lo, hi))``: a random count in [lo, hi) of each, in order."""
    objects: list[Prism] = []
    for make, (lo, hi) in makers:
        for k in range(int(rng.integers(lo, hi))):
            objects += make(rng, planner, k)
    return objects


def cabinet(rng: np.random.Generator, planner: FloorPlanner, k: int) -> list[Prism]:
    sx, sy = float(rng.uniform(0.6, 1.2)), 0.5
    height = float(rng.uniform(0.8, 2.0))
    spot = planner.against_wall(sx, sy)
    if spot is None:
        return []
    x, y, angle = spot.x, spot.y, spot.angle
    side_shape = texture_shape(2 * (sx + sy), height)
    side = tx.cabinet(rng, side_shape, px(sx))
    if rng.random() < 0.4:  # an open shelving unit
        side[:, : px(sx)] = tx.bookshelf(rng, (side_shape[0], px(sx)), px(0.025))
    cap = tx.wood(rng, texture_shape(sx, sy))
    return [Box(f"cabinet_{k}", 0.0, height, side, cap, centre=(x, y), size=(sx, sy), angle=angle)]


def box_stack(rng: np.random.Generator, planner: FloorPlanner, k: int) -> list[Prism]:
    size = float(rng.uniform(0.3, 0.6))
    spot = planner.spot(size * 0.75)
    if spot is None:
        return []
    x, y, angle = spot
    out: list[Prism] = []
    z = 0.0
    for level in range(int(rng.integers(1, 3))):
        s = size * (1.0 - 0.25 * level)
        h = float(rng.uniform(0.25, 0.5))
        side = tx.cardboard(rng, texture_shape(4 * s, h))
        cap = tx.cardboard(rng, texture_shape(s, s))
        out.append(
            Box(
                f"box_{k}_{level}",
                z,
                z + h,
                side,
                cap,
                centre=(x, y),
                size=(s, s),
                angle=angle + 0.3 * level,
            )
        )
        z += h
    return out


def waste_bin(
    rng: np.random.Generator,
    planner: FloorPlanner,
    k: int,
    walls: tuple[int, ...] | None = None,
) -> list[Prism]:
    """A round bin standing free, or against one of ``walls`` if given."""
    radius, height = float(rng.uniform(0.15, 0.25)), float(rng.uniform(0.4, 0.7))
    if walls is None:
        spot = planner.spot(radius)
    else:
        at_wall = planner.against_wall(2 * radius, 2 * radius, walls)
        spot = None if at_wall is None else (at_wall.x, at_wall.y, 0.0)
    if spot is None:
        return []
    x, y, _ = spot
    side = tx.striped(rng, texture_shape(2 * np.pi * radius, height))
    cap = tx.blank(texture_shape(2 * radius, 2 * radius), 0.1)
    return [Cylinder(f"bin_{k}", 0.0, height, side, cap, centre=(x, y), radius=radius)]


def legs(
    rng: np.random.Generator,
    name: str,
    centre: tuple[float, float],
    size: tuple[float, float],
    angle: float,
    height: float,
    variant: str | None = None,
) -> list[Prism]:
    """Four square legs under the corners of a rotated rectangle."""
    thick = 0.04
    ca, sa = np.cos(angle), np.sin(angle)
    out: list[Prism] = []
    for k, (fx, fy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
        lx, ly = fx * (size[0] / 2 - thick), fy * (size[1] / 2 - thick)
        c = (centre[0] + lx * ca - ly * sa, centre[1] + lx * sa + ly * ca)
        side = tx.metal(rng, texture_shape(4 * thick, height)) * 0.4
        cap = tx.blank(texture_shape(thick, thick), 0.2)
        out.append(
            Box(
                f"{name}/leg_{k}",
                0.0,
                height,
                side,
                cap,
                centre=c,
                size=(thick, thick),
                angle=angle,
                variant=variant,
            )
        )
    return out


def table(rng: np.random.Generator, planner: FloorPlanner, k: int) -> list[Prism]:
    sx, sy = float(rng.uniform(0.8, 1.6)), float(rng.uniform(0.6, 0.9))
    spot = planner.spot(float(np.hypot(sx, sy)) / 2)
    if spot is None:
        return []
    x, y, angle = spot
    top_z = 0.72
    side = tx.wood(rng, texture_shape(2 * (sx + sy), 0.04))
    out: list[Prism] = [
        Box(
            f"table_{k}/top",
            top_z,
            top_z + 0.04,
            side,
            tx.wood(rng, texture_shape(sx, sy)),
            centre=(x, y),
            size=(sx, sy),
            angle=angle,
        )
    ]
    out += legs(rng, f"table_{k}", (x, y), (sx, sy), angle, top_z)
    s, h = float(rng.uniform(0.2, 0.35)), float(rng.uniform(0.15, 0.45))
    out.append(
        Box(
            f"table_{k}/item",
            top_z + 0.04,
            top_z + 0.04 + h,
            tx.cardboard(rng, texture_shape(4 * s, h)),
            tx.cardboard(rng, texture_shape(s, s)),
            centre=(x, y),
            size=(s, s),
            angle=angle + float(rng.uniform(-0.5, 0.5)),
        )
    )
    return out


# --------------------------------------------------------------------------- variants


def _cameras(grid: Grid, camera_height: float) -> np.ndarray:
    """All camera positions (n, 3)."""
    xy = grid.position(*np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1])))
    xy = xy.reshape(-1, 2)
    return np.column_stack([xy, np.full(len(xy), camera_height)])


def _clear_of(parts: list[Prism], cameras: np.ndarray, room: Room) -> bool:
    """Whether every part is inside the room and keeps clear of every camera."""
    for part in parts:
        ring = part.outline()
        if ring.min() <= 0.02 or ring[:, 0].max() >= room.width - 0.02:
            return False
        if ring[:, 1].max() >= room.depth - 0.02 or part.z1 >= room.height:
            return False
        if any(part.clearance(*c) < CAMERA_CLEARANCE for c in cameras):
            return False
    return True


def _plant(rng: np.random.Generator, grid: Grid, camera_height: float, room: Room) -> list[Prism]:
    """A potted plant in a grid cell: pot, trunk and clumps of leaves."""
    s = grid.spacing
    i = np.arange(-1, grid.shape[0]) + 0.5
    j = np.arange(-1, grid.shape[1]) + 0.5
    inside = [
        (a, b) for a in i for b in j if 0 < a < grid.shape[0] - 1 and 0 < b < grid.shape[1] - 1
    ]
    cells = inside or [(a, b) for a in i for b in j]
    a, b = cells[int(rng.integers(len(cells)))]
    cx, cy = (float(v) for v in grid.position(a, b))
    cameras = _cameras(grid, camera_height)
    reach = s * np.sqrt(0.5) - CAMERA_CLEARANCE - 0.01  # pot radius that misses the cameras
    pot = (float(np.clip(reach, 0.05, 0.16)), float(rng.uniform(0.3, 0.45)))
    top = float(min(rng.uniform(1.7, 2.2), room.height - 0.1))
    parts = potted_plant(
        rng, "plant", (cx, cy), pot, top, lambda p: _clear_of(p, cameras, room), "arboreal"
    )
    if not parts:
        raise ConfigError(f"grid spacing {s} m leaves no room for the arboreal plant's pot")
    return parts


def potted_plant(
    rng: np.random.Generator,
    name: str,
    centre: tuple[float, float],
    pot: tuple[float, float],
    top: float,
    fits: Callable[[list[Prism]], bool],
    variant: str | None = None,
) -> list[Prism]:
    """A pot of ``pot`` = (radius, height) metres at ``centre``, a trunk up to ``top`` metres
    and 6-10 clumps of leaves; ``fits`` accepts the pot and trunk (else []) and each clump."""
    (cx, cy), (pot_r, pot_h) = centre, pot
    parts: list[Prism] = [
        Cylinder(
            f"{name}/pot",
            0.0,
            pot_h,
            tx.striped(rng, texture_shape(2 * np.pi * pot_r, pot_h)),
            tx.blank(texture_shape(2 * pot_r, 2 * pot_r), 0.15),
            centre=centre,
            radius=pot_r,
            variant=variant,
        ),
        Cylinder(
            f"{name}/trunk",
            pot_h,
            top,
            tx.bark(rng, texture_shape(0.16, top)),
            tx.blank(texture_shape(0.05, 0.05), 0.2),
            centre=centre,
            radius=0.025,
            variant=variant,
        ),
    ]
    if not fits(parts):
        return []
    n_clumps = int(rng.integers(6, 11))
    for k in range(n_clumps):
        for _ in range(ATTEMPTS):
            z0 = float(rng.uniform(pot_h + 0.3, top - 0.15))
            h = float(rng.uniform(0.15, 0.35))
            r = float(rng.uniform(0.08, 0.3))
            off = rng.uniform(-0.08, 0.08, size=2)
            leaf = Cylinder(
                f"{name}/leaves_{k}",
                z0,
                min(z0 + h, top),
                tx.foliage(rng, texture_shape(2 * np.pi * r, h)),
                tx.foliage(rng, texture_shape(2 * r, 2 * r)),
                centre=(cx + float(off[0]), cy + float(off[1])),
                radius=r,
                variant=variant,
            )
            if fits([leaf]):
                parts.append(leaf)
                break
    return parts


def _chair(
    rng: np.random.Generator, k: int, centre: tuple[float, float], angle: float
) -> list[Prism]:
    """Seat, backrest and four legs; the backrest stands along the local +y edge."""
    w, seat_z = float(rng.uniform(0.42, 0.48)), float(rng.uniform(0.42, 0.46))
    back_top = float(rng.uniform(0.8, 0.9))
    name, variant = f"chair_{k}", "chairs"
    cloth = tx.fabric(rng, texture_shape(w, w))
    parts: list[Prism] = [
        Box(
            f"{name}/seat",
            seat_z,
            seat_z + 0.04,
            tx.fabric(rng, texture_shape(4 * w, 0.04)),
            cloth,
            centre=centre,
            size=(w, w),
            angle=angle,
            variant=variant,
        ),
    ]
    ca, sa = np.cos(angle), np.sin(angle)
    ly = w / 2 - 0.02
    back_c = (centre[0] - ly * sa, centre[1] + ly * ca)
    parts.append(
        Box(
            f"{name}/back",
            seat_z + 0.04,
            back_top,
            tx.fabric(rng, texture_shape(2 * (w + 0.04), back_top - seat_z)),
            cloth[:4, :],
            centre=back_c,
            size=(w, 0.04),
            angle=angle,
            variant=variant,
        )
    )
    parts += legs(rng, name, centre, (w, w), angle, seat_z, variant)
    return parts


def _disc(part: Prism) -> tuple[float, float, float]:
    """Bounding disc (x, y, radius) of a footprint."""
    ring = part.outline()
    c = ring.mean(axis=0)
    return float(c[0]), float(c[1]), float(np.hypot(*(ring - c).T).max())


def _apart(a: Prism, b: Prism) -> bool:
    """Whether two parts' bounding discs are disjoint (or they do not overlap in height)."""
    (xa, ya, ra), (xb, yb, rb) = _disc(a), _disc(b)
    return a.z1 <= b.z0 or b.z1 <= a.z0 or float(np.hypot(xa - xb, ya - yb)) > ra + rb


def _chairs(
    rng: np.random.Generator, grid: Grid, camera_height: float, room: Room, taken: list[Prism]
) -> list[Prism]:
    """2-4 chairs in or next to the grid, clear of every camera and of other objects."""
    (gx0, gy0), (gx1, gy1) = grid.position(0, 0), grid.position(*(n - 1 for n in grid.shape))
    cameras = _cameras(grid, camera_height)
    chairs: list[Prism] = []
    for k in range(int(rng.integers(2, 5))):
        for _ in range(ATTEMPTS):
            c = (float(rng.uniform(gx0 - 0.5, gx1 + 0.5)), float(rng.uniform(gy0 - 0.5, gy1 + 0.5)))
            parts = _chair(rng, k, c, float(rng.uniform(0, 2 * np.pi)))
            apart = all(_apart(p, o) for p in parts for o in [*taken, *chairs])
            if apart and _clear_of(parts, cameras, room):
                chairs += parts
                break
    return chairs


def variant_objects(
    variant: str, seed: int, scene: Scene, grid: Grid, camera_height: float
) -> list[Prism]:
    """Objects a variant adds to the base scene ([] for the lighting variants)."""
    if variant not in _VARIANT_STREAM:
        return []
    rng = np.random.default_rng([seed, 1, _VARIANT_STREAM[variant]])
    if variant == "arboreal":
        return _plant(rng, grid, camera_height, scene.room)
    return _chairs(rng, grid, camera_height, scene.room, scene.objects)
