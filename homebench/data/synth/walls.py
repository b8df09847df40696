"""Walls and ceiling of the seeded places: fixtures on the unrolled walls, the wall canvas,
windows with venetian blinds, office doors with room signs, and the ceiling's luminaires.

Wall coordinates: a fixture spans ``along`` metres into one wall (0=S, 1=W, 2=N, 3=E, in the
room's unrolling order, see :class:`~homebench.data.synth.scene.Room`) and ``z`` metres above
the floor. Everything here draws only from the generator it is given.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    LightBar,
    Room,
    Surface,
    Window,
    texture_shape,
)

#: Tries of every rejection sampler before it gives up on an item.
ATTEMPTS = 200


def px(metres: float) -> int:
    """Texels of ``metres`` on a texture."""
    return int(round(metres * TEXELS_PER_METRE))


@dataclass(frozen=True)
class Fixture:
    """A rectangle on one wall: ``along`` and ``z`` spans in metres."""

    wall: int
    along: tuple[float, float]
    z: tuple[float, float]

    def overlaps(self, other: Fixture, margin: float) -> bool:
        return (
            self.wall == other.wall
            and self.along[0] < other.along[1] + margin
            and other.along[0] < self.along[1] + margin
            and self.z[0] < other.z[1] + margin
            and other.z[0] < self.z[1] + margin
        )


class WallPlanner:
    """Places non-overlapping fixtures on the four walls by rejection sampling."""

    def __init__(self, rng: np.random.Generator, room: Room):
        self.rng, self.room = rng, room
        self.placed: list[Fixture] = []

    def place(
        self,
        width: float,
        z: tuple[float, float],
        walls: tuple[int, ...] = (0, 1, 2, 3),
        accept: Callable[[Fixture], bool] | None = None,
    ) -> Fixture | None:
        """A free fixture ``width`` metres wide over ``z`` on one of ``walls``, or None.

        ``accept`` (optional) is asked last, about a fixture that is otherwise free; it may
        reserve what goes with the fixture (e.g. floor space), since True places it.
        """
        for _ in range(ATTEMPTS):
            wall = int(self.rng.choice(walls))
            length = self.room.wall_length(wall)
            if width > length - 0.4:
                continue
            a0 = float(self.rng.uniform(0.2, length - 0.2 - width))
            fixture = Fixture(wall, (a0, a0 + width), z)
            if self.free(fixture) and (accept is None or accept(fixture)):
                self.placed.append(fixture)
                return fixture
        return None

    def free(self, fixture: Fixture) -> bool:
        """Whether ``fixture`` keeps 0.1 m from every placed one."""
        return not any(fixture.overlaps(f, 0.1) for f in self.placed)


@dataclass
class WallCanvas:
    """The unrolled wall texture (closed curtains), its open-curtain copy and the glow mask."""

    room: Room
    closed: tx.Texture
    opened: tx.Texture
    glow: tx.Texture

    @classmethod
    def plain(cls, room: Room, albedo: tx.Texture) -> WallCanvas:
        """A canvas of ``albedo`` (rows, cols of the unrolled walls) in both states, no glow."""
        return cls(room, albedo, albedo.copy(), np.zeros(albedo.shape, np.float32))

    def rect(self, f: Fixture) -> tuple[int, int, int, int]:
        """Pixel rectangle (r0, c0, r1, c1) of a fixture."""
        u0 = self.room.wall_u(f.wall, f.along[0])
        return (
            px(self.room.height - f.z[1]),
            px(u0),
            px(self.room.height - f.z[0]),
            px(u0 + f.along[1] - f.along[0]),
        )

    def shape(self, f: Fixture) -> tuple[int, int]:
        """Pixel shape (rows, cols) of a fixture."""
        r0, c0, r1, c1 = self.rect(f)
        return r1 - r0, c1 - c0

    def put(
        self,
        f: Fixture,
        closed: tx.Texture,
        opened: tx.Texture | None = None,
        glow: tx.Texture | None = None,
    ) -> None:
        """Write patches of the fixture's shape: ``closed`` on the shut albedo, ``opened``
        (default ``closed``) on the open one, ``glow`` (if given) on the glow mask. NaN texels
        of a patch keep what is there."""
        r0, c0, r1, c1 = self.rect(f)
        targets = ((self.closed, closed), (self.opened, closed if opened is None else opened))
        for tex, patch in (*targets, (self.glow, glow)):
            if patch is not None:
                np.copyto(tex[r0:r1, c0:c1], patch, where=~np.isnan(patch))

    def paint(self, f: Fixture, make: tx.Painter) -> None:
        """Paint the same patch on both albedos; NaN texels of the patch keep the wall."""
        self.put(f, make(self.shape(f)))

    def band(self, wall: int, z: tuple[float, float], value: float) -> None:
        """Paint a horizontal band over ``z`` metres along the whole of ``wall`` (both albedos)."""
        self.put(Fixture(wall, (0.0, self.room.wall_length(wall)), z), np.float32(value))

    def skirting(self, height: float = 0.08, grey: float = 0.25, edge: float = 0.45) -> None:
        """A skirting board of ``height`` metres round every wall, with a lighter top edge."""
        rows = px(height)
        for tex in (self.closed, self.opened):
            tex[-rows:, :] = grey
            tex[-rows, :] = edge

    def surface(self) -> Surface:
        """The walls as a surface (window glow)."""
        return Surface(
            self.closed,
            (self.room.perimeter, self.room.height),
            self.room.place_wall,
            albedo_open=self.opened,
            glow=self.glow,
            glow_kind="window",
        )


#: Fixtures to hang: (width range, z span) in metres and the painter of each.
Plan = list[tuple[tuple[float, float], tuple[float, float], tx.Painter]]


def hang(
    rng: np.random.Generator,
    canvas: WallCanvas,
    planner: WallPlanner,
    plan: Plan,
    walls: tuple[int, ...] = (0, 1, 2, 3),
) -> list[Fixture]:
    """Place each fixture of ``plan`` (in order; a width drawn from its range) on one of
    ``walls`` where it fits, and paint it; a fixture that finds no room is left out.
    Returns the placed fixtures."""
    placed = []
    for widths, z, painter in plan:
        f = planner.place(float(rng.uniform(*widths)), z, walls)
        if f is not None:
            canvas.paint(f, painter)
            placed.append(f)
    return placed


def bays(length: float, n: int, width: float) -> list[tuple[float, float]]:
    """``n`` spans of ``width`` metres, one centred in each of ``n`` equal bays of a wall of
    ``length`` metres (a facade's regular window rhythm)."""
    pitch = length / n
    return [((k + 0.5) * pitch - width / 2, (k + 0.5) * pitch + width / 2) for k in range(n)]


def blind_windows(
    rng: np.random.Generator,
    canvas: WallCanvas,
    planner: WallPlanner,
    wall: int,
    spans: list[tuple[float, float]],
    z: tuple[float, float],
) -> list[Window]:
    """Windows with venetian blinds over ``spans`` (along ``wall``) and ``z``, reserved in the
    planner, with a radiator under each whose sill is high enough.

    The blinds share one colour. Shut, every blind is down; open, 60 % are raised and the rest
    lowered to 50-90 % of the height with their slats tilted open
    (:func:`~textures.venetian_window`).
    """
    windows = []
    grey = float(rng.uniform(0.6, 0.8))
    for along in spans:
        f = Fixture(wall, along, z)
        planner.placed.append(f)
        lowered = 0.0 if rng.random() < 0.6 else float(rng.uniform(0.5, 0.9))
        canvas.put(f, *tx.venetian_window(rng, canvas.shape(f), px(0.06), 3, grey, lowered))
        windows.append(Window(wall, along, z))
        if z[0] >= 0.8:
            radiator = Fixture(wall, (along[0] + 0.15, along[1] - 0.15), (0.15, z[0] - 0.15))
            planner.placed.append(radiator)
            canvas.paint(radiator, lambda shape: tx.radiator(rng, shape))
    return windows


#: An office door's fixture: the door (frame included) and its room sign beside it, metres.
DOOR_WIDTH, DOOR_HEIGHT, DOOR_SPAN = 1.0, 2.1, 1.4


def office_door(
    rng: np.random.Generator,
    canvas: WallCanvas,
    f: Fixture,
    look: tuple[float, float],
    vision: bool,
    number: str,
) -> None:
    """Paint a flush office door (:func:`~textures.office_door`, ``look`` = its building's
    (leaf, frame) greys, a vision panel if ``vision``) at the start of fixture ``f``
    (``DOOR_SPAN`` wide, from the floor) and its room sign showing ``number`` 0.1 m beyond
    it, 1.4-1.6 m up."""
    a = f.along[0]
    door = Fixture(f.wall, (a, a + DOOR_WIDTH), (0.0, DOOR_HEIGHT))
    panel = tx.VISION_PANEL if vision else None
    albedo, glow = tx.office_door(rng, canvas.shape(door), *look, panel)
    canvas.put(door, albedo, glow=glow)
    sign = Fixture(f.wall, (a + DOOR_WIDTH + 0.1, a + DOOR_WIDTH + 0.35), (1.4, 1.6))
    canvas.paint(sign, lambda shape: tx.door_sign(rng, shape, number))


@dataclass(frozen=True)
class LightGrid:
    """Ceiling luminaires on a regular grid, evenly spread over the room.

    ``pitch`` (x, y): nominal metres between centres (the count along each axis is the room's
    extent / pitch, rounded, at least 1); ``size`` (x, y): each luminaire's extent in metres
    (its light bar runs along the longer side); ``louvres``: cross blades of each
    (:func:`~homebench.data.synth.textures.luminaire`).
    """

    pitch: tuple[float, float] = (2.0, 2.5)
    size: tuple[float, float] = (0.16, 1.2)
    louvres: int = 0

    def centres(self, room: Room) -> list[tuple[float, float]]:
        """Luminaire centres (x, y) in metres, row by row along x."""
        nx = max(1, round(room.width / self.pitch[0]))
        ny = max(1, round(room.depth / self.pitch[1]))
        return [
            (room.width * (i + 0.5) / nx, room.depth * (j + 0.5) / ny)
            for i in range(nx)
            for j in range(ny)
        ]


def ceiling(
    rng: np.random.Generator, room: Room, lights: LightGrid = LightGrid(), tile: float = 0.6
) -> tuple[Surface, list[LightBar]]:
    """The ceiling: acoustic tiles of ``tile`` metres with the luminaires of ``lights``
    (their glow is the light sources' emission) and the matching light bars."""
    shape = texture_shape(room.width, room.depth)
    albedo = tx.ceiling_tiles(rng, shape, TEXELS_PER_METRE, tile)
    glow = np.zeros(shape, np.float32)
    sx, sy = lights.size
    along_y = sy >= sx
    bars = []
    for x, y in lights.centres(room):
        bars.append(LightBar((x, y), max(sx, sy), np.pi / 2 if along_y else 0.0))
        r0, r1 = px(room.depth - y - sy / 2), px(room.depth - y + sy / 2)
        c0, c1 = px(x) - px(sx / 2), px(x) + px(sx / 2)
        lamp, lit = tx.luminaire((r1 - r0, c1 - c0), lights.louvres)
        tx.fill_rect(albedo, r0, c0, r1, c1, lamp)
        tx.fill_rect(glow, r0, c0, r1, c1, lit)
    surface = Surface(
        albedo,
        (room.width, room.depth),
        room.place_plane(room.height, -1.0),
        glow=glow,
        glow_kind="lights",
    )
    return surface, bars
