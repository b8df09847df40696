"""The seeded room: wall fixtures, floor, ceiling, furniture, and the variants' additions.

The base layout draws only from ``default_rng([seed, 0])``; each variant's additions draw from
their own stream ``default_rng([seed, 1, k])``, so adding a plant never moves a poster.
Objects stay outside the capture grid's footprint plus :data:`GRID_MARGIN`; the variants'
objects (plant, chairs) go in or next to the grid but keep :data:`CAMERA_CLEARANCE` metres from
every camera position.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    Box,
    Cylinder,
    LightBar,
    Prism,
    Room,
    Scene,
    Surface,
    Window,
    texture_shape,
)
from homebench.errors import ConfigError
from homebench.geometry import Grid

GRID_MARGIN = 0.4
CAMERA_CLEARANCE = 0.08
_ATTEMPTS = 200
_VARIANT_STREAM = {"arboreal": 1, "chairs": 2}


def _px(metres: float) -> int:
    return int(round(metres * TEXELS_PER_METRE))


@dataclass(frozen=True)
class _Fixture:
    """A rectangle on one wall: ``along`` and ``z`` spans in metres."""

    wall: int
    along: tuple[float, float]
    z: tuple[float, float]

    def overlaps(self, other: _Fixture, margin: float) -> bool:
        return (
            self.wall == other.wall
            and self.along[0] < other.along[1] + margin
            and other.along[0] < self.along[1] + margin
            and self.z[0] < other.z[1] + margin
            and other.z[0] < self.z[1] + margin
        )


class _WallPlanner:
    """Places non-overlapping fixtures on the four walls by rejection sampling."""

    def __init__(self, rng: np.random.Generator, room: Room):
        self.rng, self.room = rng, room
        self.placed: list[_Fixture] = []

    def place(
        self, width: float, z: tuple[float, float], walls: tuple[int, ...] = (0, 1, 2, 3)
    ) -> _Fixture | None:
        for _ in range(_ATTEMPTS):
            wall = int(self.rng.choice(walls))
            length = self.room.wall_length(wall)
            if width > length - 0.4:
                continue
            a0 = float(self.rng.uniform(0.2, length - 0.2 - width))
            fixture = _Fixture(wall, (a0, a0 + width), z)
            if not any(fixture.overlaps(f, 0.1) for f in self.placed):
                self.placed.append(fixture)
                return fixture
        return None


@dataclass
class _WallCanvas:
    """The unrolled wall texture (closed curtains), its open-curtain copy and the glow mask."""

    room: Room
    closed: tx.Texture
    opened: tx.Texture
    glow: tx.Texture

    def rect(self, f: _Fixture) -> tuple[int, int, int, int]:
        """Pixel rectangle (r0, c0, r1, c1) of a fixture."""
        u0 = self.room.wall_u(f.wall, f.along[0])
        return (
            _px(self.room.height - f.z[1]),
            _px(u0),
            _px(self.room.height - f.z[0]),
            _px(u0 + f.along[1] - f.along[0]),
        )

    def paint(self, f: _Fixture, make: Callable[[tuple[int, int]], tx.Texture]) -> None:
        """Paint the same patch on both albedos; NaN texels of the patch keep the wall."""
        r0, c0, r1, c1 = self.rect(f)
        patch = make((r1 - r0, c1 - c0))
        for tex in (self.closed, self.opened):
            region = tex[r0:r1, c0:c1]
            np.copyto(region, patch, where=~np.isnan(patch))


def _paint_walls(rng: np.random.Generator, room: Room) -> tuple[Surface, list[Window]]:
    shape = texture_shape(room.perimeter, room.height)
    base = tx.plain_wall(rng, shape)
    canvas = _WallCanvas(room, base, base.copy(), np.zeros(shape, np.float32))
    planner = _WallPlanner(rng, room)
    top = room.height - 0.25

    windows = []
    window_wall = int(rng.integers(4))
    for _ in range(2):
        f = planner.place(float(rng.uniform(1.2, 1.8)), (0.9, min(2.3, top)), (window_wall,))
        if f is None:
            continue
        windows.append(Window(f.wall, f.along, f.z))
        r0, c0, r1, c1 = canvas.rect(f)
        closed, opened, glow = tx.window(rng, (r1 - r0, c1 - c0), _px(0.06))
        canvas.closed[r0:r1, c0:c1] = closed
        canvas.opened[r0:r1, c0:c1] = opened
        canvas.glow[r0:r1, c0:c1] = glow
        rad = _Fixture(f.wall, (f.along[0] + 0.15, f.along[1] - 0.15), (0.15, 0.7))
        planner.placed.append(rad)
        canvas.paint(rad, lambda s: tx.radiator(rng, s))

    skirting = _px(0.08)
    for tex in (canvas.closed, canvas.opened):
        tex[-skirting:, :] = 0.25
        tex[-skirting, :] = 0.45
    doors = [w for w in range(4) if w != window_wall]
    for _ in range(int(rng.integers(1, 3))):
        f = planner.place(0.95, (0.0, min(2.05, top)), tuple(doors))
        if f is not None:
            canvas.paint(f, lambda s: tx.door(rng, s))
    # (width range, z span, painter) of the other fixtures, in placement order
    plan: list[tuple[tuple[float, float], tuple[float, float], Callable]] = []
    plan += [
        ((0.8, 1.6), (0.3, min(2.0, top)), lambda s: tx.bookshelf(rng, s, _px(0.025)))
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
    for widths, z, painter in plan:
        f = planner.place(float(rng.uniform(*widths)), z)
        if f is not None:
            canvas.paint(f, painter)
    for wall_index in range(4):  # pipes and trays along the top of every wall
        length = room.wall_length(wall_index)
        band = float(rng.uniform(0.12, 0.25))
        pipe = _Fixture(wall_index, (0.0, length), (room.height - 0.1 - band, room.height - 0.1))
        canvas.paint(pipe, lambda s: tx.pipes(rng, s))
    wall = Surface(
        canvas.closed,
        (room.perimeter, room.height),
        room.place_wall,
        albedo_open=canvas.opened,
        glow=canvas.glow,
        glow_kind="window",
    )
    return wall, windows


def _ceiling(rng: np.random.Generator, room: Room) -> tuple[Surface, list[LightBar]]:
    shape = texture_shape(room.width, room.depth)
    albedo = tx.ceiling_tiles(rng, shape, TEXELS_PER_METRE)
    glow = np.zeros(shape, np.float32)
    nx, ny = max(1, round(room.width / 2.0)), max(1, round(room.depth / 2.5))
    bars = []
    length, half_width = 1.2, _px(0.08)
    for i in range(nx):
        for j in range(ny):
            x, y = room.width * (i + 0.5) / nx, room.depth * (j + 0.5) / ny
            bars.append(LightBar((x, y), length, np.pi / 2))
            r0, r1 = _px(room.depth - y - length / 2), _px(room.depth - y + length / 2)
            c0, c1 = _px(x) - half_width, _px(x) + half_width
            tx.fill_rect(albedo, r0, c0, r1, c1, 0.9)
            tx.fill_rect(glow, r0, c0, r1, c1, 1.0)
            tx.frame(albedo, r0, c0, r1, c1, 3, 0.3)
            tx.frame(glow, r0, c0, r1, c1, 3, 0.0)
    surface = Surface(
        albedo,
        (room.width, room.depth),
        room.place_plane(room.height, -1.0),
        glow=glow,
        glow_kind="lights",
    )
    return surface, bars


# --------------------------------------------------------------------------- furniture


class _FloorPlanner:
    """Places objects on the floor: inside the room, off each other, away from the grid."""

    def __init__(self, rng: np.random.Generator, room: Room, keep_out: tuple[float, ...]):
        self.rng, self.room, self.keep_out = rng, room, keep_out
        self.discs: list[tuple[float, float, float]] = []

    def free(self, x: float, y: float, radius: float) -> bool:
        r = self.room
        if not (radius < x < r.width - radius and radius < y < r.depth - radius):
            return False
        x0, y0, x1, y1 = self.keep_out
        dx, dy = max(x0 - x, 0.0, x - x1), max(y0 - y, 0.0, y - y1)
        if np.hypot(dx, dy) < radius:
            return False
        return all(np.hypot(x - a, y - b) > radius + c for a, b, c in self.discs)

    def spot(self, radius: float, against_wall: bool) -> tuple[float, float, float] | None:
        """(x, y, angle) for a footprint of bounding ``radius``; walls face the front inward."""
        for _ in range(_ATTEMPTS):
            if against_wall:
                wall = int(self.rng.integers(4))
                along = float(self.rng.uniform(0, self.room.wall_length(wall)))
                x, y, nx, ny = (float(a) for a in self.room.wall_xy(self.room.wall_u(wall, along)))
                depth = float(self.rng.uniform(0.4, 0.6))
                x, y = x + nx * (depth / 2 + 0.02), y + ny * (depth / 2 + 0.02)
                angle = float(np.arctan2(nx, -ny))
            else:
                x = float(self.rng.uniform(0, self.room.width))
                y = float(self.rng.uniform(0, self.room.depth))
                angle = float(self.rng.uniform(0, np.pi))
            if self.free(x, y, radius):
                self.discs.append((x, y, radius))
                return x, y, angle
        return None


def _cabinet(rng: np.random.Generator, planner: _FloorPlanner, k: int) -> list[Prism]:
    sx, sy = float(rng.uniform(0.6, 1.2)), 0.5
    height = float(rng.uniform(0.8, 2.0))
    spot = planner.spot(float(np.hypot(sx, sy)) / 2, against_wall=True)
    if spot is None:
        return []
    x, y, angle = spot
    side_shape = texture_shape(2 * (sx + sy), height)
    side = tx.cabinet(rng, side_shape, _px(sx))
    if rng.random() < 0.4:  # an open shelving unit
        side[:, : _px(sx)] = tx.bookshelf(rng, (side_shape[0], _px(sx)), _px(0.025))
    cap = tx.wood(rng, texture_shape(sx, sy))
    return [Box(f"cabinet_{k}", 0.0, height, side, cap, centre=(x, y), size=(sx, sy), angle=angle)]


def _box_stack(rng: np.random.Generator, planner: _FloorPlanner, k: int) -> list[Prism]:
    size = float(rng.uniform(0.3, 0.6))
    spot = planner.spot(size * 0.75, against_wall=False)
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


def _bin(rng: np.random.Generator, planner: _FloorPlanner, k: int) -> list[Prism]:
    radius, height = float(rng.uniform(0.15, 0.25)), float(rng.uniform(0.4, 0.7))
    spot = planner.spot(radius, against_wall=False)
    if spot is None:
        return []
    x, y, _ = spot
    side = tx.striped(rng, texture_shape(2 * np.pi * radius, height))
    cap = tx.blank(texture_shape(2 * radius, 2 * radius), 0.1)
    return [Cylinder(f"bin_{k}", 0.0, height, side, cap, centre=(x, y), radius=radius)]


def _legs(
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


def _table(rng: np.random.Generator, planner: _FloorPlanner, k: int) -> list[Prism]:
    sx, sy = float(rng.uniform(0.8, 1.6)), float(rng.uniform(0.6, 0.9))
    spot = planner.spot(float(np.hypot(sx, sy)) / 2, against_wall=False)
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
    out += _legs(rng, f"table_{k}", (x, y), (sx, sy), angle, top_z)
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


def base_scene(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded room without any variant additions."""
    rng = np.random.default_rng([seed, 0])
    wall, windows = _paint_walls(rng, room)
    floor = Surface(
        tx.floor(rng, texture_shape(room.width, room.depth), TEXELS_PER_METRE),
        (room.width, room.depth),
        room.place_plane(0.0, 1.0),
    )
    ceiling, bars = _ceiling(rng, room)
    (gx0, gy0), (gx1, gy1) = grid.position(0, 0), grid.position(*(n - 1 for n in grid.shape))
    keep_out = (gx0 - GRID_MARGIN, gy0 - GRID_MARGIN, gx1 + GRID_MARGIN, gy1 + GRID_MARGIN)
    planner = _FloorPlanner(rng, room, keep_out)
    objects: list[Prism] = []
    makers = [(_cabinet, (3, 7)), (_table, (1, 3)), (_box_stack, (3, 7)), (_bin, (1, 4))]
    for make, (lo, hi) in makers:
        for k in range(int(rng.integers(lo, hi))):
            objects += make(rng, planner, k)
    return Scene(room, wall, floor, ceiling, objects, windows, bars)


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
    room_top = room.height - 0.1
    reach = s * np.sqrt(0.5) - CAMERA_CLEARANCE - 0.01  # pot radius that misses the cameras
    variant = "arboreal"
    pot_r, pot_h = float(np.clip(reach, 0.05, 0.16)), float(rng.uniform(0.3, 0.45))
    top = float(min(rng.uniform(1.7, 2.2), room_top))
    parts: list[Prism] = [
        Cylinder(
            "plant/pot",
            0.0,
            pot_h,
            tx.striped(rng, texture_shape(2 * np.pi * pot_r, pot_h)),
            tx.blank(texture_shape(2 * pot_r, 2 * pot_r), 0.15),
            centre=(cx, cy),
            radius=pot_r,
            variant=variant,
        ),
        Cylinder(
            "plant/trunk",
            pot_h,
            top,
            tx.bark(rng, texture_shape(0.16, top)),
            tx.blank(texture_shape(0.05, 0.05), 0.2),
            centre=(cx, cy),
            radius=0.025,
            variant=variant,
        ),
    ]
    if not _clear_of(parts, cameras, room):
        raise ConfigError(f"grid spacing {s} m leaves no room for the arboreal plant's pot")
    n_clumps = int(rng.integers(6, 11))
    for k in range(n_clumps):
        for _ in range(_ATTEMPTS):
            z0 = float(rng.uniform(pot_h + 0.3, top - 0.15))
            h = float(rng.uniform(0.15, 0.35))
            r = float(rng.uniform(0.08, 0.3))
            off = rng.uniform(-0.08, 0.08, size=2)
            leaf = Cylinder(
                f"plant/leaves_{k}",
                z0,
                min(z0 + h, top),
                tx.foliage(rng, texture_shape(2 * np.pi * r, h)),
                tx.foliage(rng, texture_shape(2 * r, 2 * r)),
                centre=(cx + float(off[0]), cy + float(off[1])),
                radius=r,
                variant=variant,
            )
            if _clear_of([leaf], cameras, room):
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
    parts += _legs(rng, name, centre, (w, w), angle, seat_z, variant)
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
        for _ in range(_ATTEMPTS):
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
