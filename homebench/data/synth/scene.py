"""Scene description: a box-shaped room, its textured surfaces and vertical-prism objects.

Every object is a vertical prism (a footprint extruded from ``z0`` to ``z1``): a box rotatable
about z or a vertical cylinder. That keeps ray casting separable (see ``raycast.py``): a ray's
horizontal direction decides where it crosses a footprint, its elevation where it crosses a
height.

Texture coordinates (u, v) are metres on a surface: u along its columns, v down its rows from
the top. Sides unroll counter-clockwise seen from above (so that text reads correctly from
outside); the room's walls unroll clockwise from the corner (width, 0) (readable from inside).
Textures need not share one density: a far wall may hold a few texels per metre, and
floor :class:`Patch` es add detail where the cameras look closely.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import InitVar, dataclass, field
from functools import cached_property
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from homebench.data.synth.textures import Texture

FloatArray = NDArray[np.float64]
Placement = Callable[[FloatArray, FloatArray], tuple[FloatArray, FloatArray]]
#: Footprint crossing of horizontal rays, each (n,): entry and exit distance, u at the entry
#: (exit for the room), |cos| of the horizontal incidence angle there.
Crossing = tuple[FloatArray, FloatArray, FloatArray, FloatArray]

TEXELS_PER_METRE = 100.0
_TINY = 1e-12
_SELF = 1e-3  # metres a shadow ray travels before it can be blocked


def texture_shape(
    u_metres: float, v_metres: float, density: float = TEXELS_PER_METRE
) -> tuple[int, int]:
    """Pixel shape (rows, cols) of a texture covering ``u_metres`` x ``v_metres`` at
    ``density`` texels per metre."""
    cols = max(2, int(np.ceil(u_metres * density)))
    rows = max(2, int(np.ceil(v_metres * density)))
    return rows, cols


def _nonzero(a: FloatArray) -> FloatArray:
    return np.where(np.abs(a) < _TINY, _TINY, a)


def _slabs(
    o: float | FloatArray, d: FloatArray, lo: float, hi: float
) -> tuple[FloatArray, FloatArray]:
    """Ray distances where ``o + t * d`` enters / leaves [lo, hi]; ``o`` and ``d`` broadcast."""
    inv = 1.0 / _nonzero(d)
    t1, t2 = (lo - o) * inv, (hi - o) * inv
    return np.minimum(t1, t2), np.maximum(t1, t2)


@dataclass(eq=False)
class Surface:
    """A textured rectangle in (u, v) metres and where it lies in the world.

    ``albedo``: (rows, cols) in [0, 1] over ``size`` = (u extent, v extent). ``place`` maps
    (u, v) arrays to world points and unit normals, each (..., 3). ``albedo_open`` replaces the
    albedo when curtains are open; ``glow`` (same shape, >= 0) is an emission pattern switched
    by the lighting (``glow_kind``). A texture may have any density (:attr:`scale`): the
    renderer chooses mip levels from each hit's own density.
    """

    albedo: Texture
    size: tuple[float, float]
    place: Placement
    albedo_open: Texture | None = None
    glow: Texture | None = None
    glow_kind: Literal["lights", "window", "sky"] | None = None

    def __post_init__(self) -> None:
        self.albedo = np.clip(self.albedo, 0.0, 1.0).astype(np.float32)
        if self.albedo_open is not None:
            self.albedo_open = np.clip(self.albedo_open, 0.0, 1.0).astype(np.float32)

    @property
    def scale(self) -> tuple[float, float]:
        """Texels per metre along u and v."""
        rows, cols = self.albedo.shape
        return cols / self.size[0], rows / self.size[1]


def _stack(x: FloatArray, y: FloatArray, z: FloatArray | float) -> FloatArray:
    x, y, z = np.broadcast_arrays(x, y, z)
    return np.stack([x, y, z], axis=-1).astype(np.float64)


# --------------------------------------------------------------------------- prisms


@dataclass(eq=False)
class Prism(ABC):
    """A vertical prism from ``z0`` to ``z1`` with a convex footprint (abstract)."""

    name: str
    z0: float
    z1: float
    side: Texture
    cap: Texture
    variant: str | None = field(default=None, kw_only=True)
    kind: ClassVar[str] = "prism"

    @abstractmethod
    def crossing(self, ox: float, oy: float, c: FloatArray, s: FloatArray) -> Crossing:
        """Where horizontal rays from (ox, oy) along (c, s) (each (n,)) cross the footprint.

        The origin may also be arrays (n,): one ray per origin.
        """

    @property
    @abstractmethod
    def perimeter(self) -> float:
        """Length of the footprint outline, metres (the side texture's u extent)."""

    @property
    @abstractmethod
    def cap_size(self) -> tuple[float, float]:
        """(u, v) extent of the cap texture, metres."""

    @abstractmethod
    def cap_uv(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Cap texture coordinates of world points (x, y)."""

    @abstractmethod
    def _cap_xy(self, u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Inverse of :meth:`cap_uv`."""

    @abstractmethod
    def _side_xy(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """World x, y and outward normal (nx, ny) at perimeter coordinate u."""

    @abstractmethod
    def outline(self) -> FloatArray:
        """Footprint outline points (n, 2): box corners or a ring around a cylinder."""

    @abstractmethod
    def distance_xy(self, x: float, y: float) -> float:
        """Signed horizontal distance from the footprint (negative inside)."""

    # -- shared
    @cached_property
    def bounds(self) -> FloatArray:
        """Bounding box (4,) of the footprint: min x, min y, max x, max y."""
        ring = self.outline()
        return np.concatenate([ring.min(axis=0), ring.max(axis=0)])

    def blocks(self, points: FloatArray, direction: FloatArray) -> NDArray[np.bool_]:
        """Whether rays from ``points`` (n, 3) towards ``direction`` (3,), a unit vector above
        the horizon, pass through the solid (n,). Points on its surface do not block
        themselves."""
        horizontal = float(np.hypot(direction[0], direction[1]))
        c, s = np.array(direction[0] / horizontal), np.array(direction[1] / horizontal)
        rho_in, rho_out, _, _ = self.crossing(points[:, 0], points[:, 1], c, s)
        slope = direction[2] / horizontal  # metres up per metre along the ground
        low, high = (self.z0 - points[:, 2]) / slope, (self.z1 - points[:, 2]) / slope
        return np.minimum(rho_out, high) > np.maximum(np.maximum(rho_in, low), _SELF)

    def clearance(self, x: float, y: float, z: float) -> float:
        """Distance in metres from a point to the solid (0 inside)."""
        dxy = max(self.distance_xy(x, y), 0.0)
        dz = max(self.z0 - z, z - self.z1, 0.0)
        return float(np.hypot(dxy, dz))

    def corners(self) -> list[list[float]]:
        """3-D points [[x, y, z], ...] of the outline at the bottom, then at the top."""
        ring = self.outline()
        return [[float(x), float(y), float(z)] for z in (self.z0, self.z1) for x, y in ring]

    def surfaces(self) -> tuple[Surface, Surface, Surface]:
        """(side, top, bottom) surfaces; top and bottom share the cap texture."""

        def side(u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
            x, y, nx, ny = self._side_xy(u)
            return _stack(x, y, self.z1 - v), _stack(nx, ny, 0.0)

        def cap(z: float, nz: float) -> Placement:
            def place(u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
                x, y = self._cap_xy(u, v)
                return _stack(x, y, z), _stack(0.0 * x, 0.0 * y, nz)

            return place

        height = self.z1 - self.z0
        return (
            Surface(self.side, (self.perimeter, height), side),
            Surface(self.cap, self.cap_size, cap(self.z1, 1.0)),
            Surface(self.cap, self.cap_size, cap(self.z0, -1.0)),
        )


@dataclass(eq=False)
class Box(Prism):
    """A box of ``size`` = (sx, sy) metres centred at ``centre``, turned ``angle`` rad about z.

    Its sides unroll from the local corner (-sx/2, -sy/2): the -y face first (the front), then
    +x, +y, -x.
    """

    centre: tuple[float, float] = (0.0, 0.0)
    size: tuple[float, float] = (1.0, 1.0)
    angle: float = 0.0
    kind: ClassVar[str] = "box"

    def _to_local(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        ca, sa = np.cos(self.angle), np.sin(self.angle)
        dx, dy = np.asarray(x) - self.centre[0], np.asarray(y) - self.centre[1]
        return dx * ca + dy * sa, -dx * sa + dy * ca

    def _to_world(self, lx: FloatArray, ly: FloatArray) -> tuple[FloatArray, FloatArray]:
        ca, sa = np.cos(self.angle), np.sin(self.angle)
        return self.centre[0] + lx * ca - ly * sa, self.centre[1] + lx * sa + ly * ca

    def crossing(self, ox: float, oy: float, c: FloatArray, s: FloatArray) -> Crossing:
        hx, hy = self.size[0] / 2, self.size[1] / 2
        lx, ly = self._to_local(ox, oy)
        ca, sa = np.cos(self.angle), np.sin(self.angle)
        dx, dy = c * ca + s * sa, -c * sa + s * ca
        txa, txb = _slabs(lx, dx, -hx, hx)
        tya, tyb = _slabs(ly, dy, -hy, hy)
        rho_in, rho_out = np.maximum(txa, tya), np.minimum(txb, tyb)
        px, py = lx + rho_in * dx, ly + rho_in * dy
        sx, sy = self.size
        x_face = txa > tya
        u_x = np.where(dx > 0, 2 * sx + sy + (hy - py), sx + (py + hy))
        u_y = np.where(dy > 0, px + hx, sx + sy + (hx - px))
        u = np.where(x_face, u_x, u_y)
        cos_h = np.where(x_face, np.abs(dx), np.abs(dy))
        return rho_in, rho_out, u, cos_h

    @property
    def perimeter(self) -> float:
        return 2.0 * (self.size[0] + self.size[1])

    @property
    def cap_size(self) -> tuple[float, float]:
        return self.size

    def cap_uv(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        lx, ly = self._to_local(x, y)
        return lx + self.size[0] / 2, self.size[1] / 2 - ly

    def _cap_xy(self, u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self._to_world(u - self.size[0] / 2, self.size[1] / 2 - v)

    def _side_xy(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        sx, sy = self.size
        hx, hy = sx / 2, sy / 2
        u = np.asarray(u, np.float64)
        edges = [u < sx, u < sx + sy, u < 2 * sx + sy, np.ones_like(u, bool)]
        lx = np.select(edges, [u - hx, hx + 0 * u, hx - (u - sx - sy), -hx + 0 * u])
        ly = np.select(edges, [-hy + 0 * u, u - sx - hy, hy + 0 * u, hy - (u - 2 * sx - sy)])
        nlx = np.select(edges, [0.0, 1.0, 0.0, -1.0])
        nly = np.select(edges, [-1.0, 0.0, 1.0, 0.0])
        x, y = self._to_world(lx, ly)
        ca, sa = np.cos(self.angle), np.sin(self.angle)
        return x, y, nlx * ca - nly * sa, nlx * sa + nly * ca

    def outline(self) -> FloatArray:
        hx, hy = self.size[0] / 2, self.size[1] / 2
        lx, ly = np.array([-hx, hx, hx, -hx]), np.array([-hy, -hy, hy, hy])
        return np.stack(self._to_world(lx, ly), axis=-1)

    def distance_xy(self, x: float, y: float) -> float:
        lx, ly = self._to_local(x, y)
        qx, qy = abs(float(lx)) - self.size[0] / 2, abs(float(ly)) - self.size[1] / 2
        return float(np.hypot(max(qx, 0.0), max(qy, 0.0)) + min(max(qx, qy), 0.0))


@dataclass(eq=False)
class Cylinder(Prism):
    """A vertical cylinder of ``radius`` metres around ``centre``; sides unroll from +x."""

    centre: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.5
    kind: ClassVar[str] = "cylinder"
    ring_points: ClassVar[int] = 16

    def crossing(self, ox: float, oy: float, c: FloatArray, s: FloatArray) -> Crossing:
        px, py = ox - self.centre[0], oy - self.centre[1]
        b = px * c + py * s
        disc = b * b - (px * px + py * py - self.radius**2)
        root = np.sqrt(np.maximum(disc, 0.0))
        miss = disc < 0
        rho_in = np.where(miss, np.inf, -b - root)
        rho_out = np.where(miss, -np.inf, -b + root)
        angle = np.arctan2(py + rho_in * s, px + rho_in * c) % (2 * np.pi)
        return rho_in, rho_out, self.radius * angle, root / self.radius

    @property
    def perimeter(self) -> float:
        return 2.0 * np.pi * self.radius

    @property
    def cap_size(self) -> tuple[float, float]:
        return 2 * self.radius, 2 * self.radius

    def cap_uv(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        return x - self.centre[0] + self.radius, self.radius - (y - self.centre[1])

    def _cap_xy(self, u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        return u + self.centre[0] - self.radius, self.centre[1] + self.radius - v

    def _side_xy(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        a = np.asarray(u, np.float64) / self.radius
        nx, ny = np.cos(a), np.sin(a)
        return self.centre[0] + self.radius * nx, self.centre[1] + self.radius * ny, nx, ny

    def outline(self) -> FloatArray:
        a = np.linspace(0, 2 * np.pi, self.ring_points, endpoint=False)
        return np.stack(self._side_xy(self.radius * a)[:2], axis=-1)

    def distance_xy(self, x: float, y: float) -> float:
        return float(np.hypot(x - self.centre[0], y - self.centre[1]) - self.radius)


# --------------------------------------------------------------------------- the room


@dataclass(frozen=True)
class Room:
    """The inside of the box [0, width] x [0, depth] x [0, height] (metres)."""

    width: float
    depth: float
    height: float

    @property
    def perimeter(self) -> float:
        return 2.0 * (self.width + self.depth)

    def crossing(self, ox: float, oy: float, c: FloatArray, s: FloatArray) -> Crossing:
        """Where horizontal rays from inside leave the footprint (rho_in is 0)."""
        _, txb = _slabs(ox, c, 0.0, self.width)
        _, tyb = _slabs(oy, s, 0.0, self.depth)
        rho = np.minimum(txb, tyb)
        px, py = ox + rho * c, oy + rho * s
        w, d = self.width, self.depth
        x_face = txb < tyb
        u_x = np.where(c > 0, 2 * w + d + (d - py), w + py)
        u_y = np.where(s > 0, w + d + px, w - px)
        u = np.where(x_face, u_x, u_y)
        return np.zeros_like(rho), rho, u, np.where(x_face, np.abs(c), np.abs(s))

    def wall_xy(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """World x, y and inward normal at wall coordinate u (clockwise from (width, 0))."""
        w, d = self.width, self.depth
        u = np.asarray(u, np.float64) % self.perimeter
        edges = [u < w, u < w + d, u < 2 * w + d, np.ones_like(u, bool)]
        x = np.select(edges, [w - u, 0 * u, u - w - d, w + 0 * u])
        y = np.select(edges, [0 * u, u - w, d + 0 * u, d - (u - 2 * w - d)])
        nx = np.select(edges, [0.0, 1.0, 0.0, -1.0])
        ny = np.select(edges, [1.0, 0.0, -1.0, 0.0])
        return x, y, nx, ny

    def wall_u(self, wall: int, along: float) -> float:
        """Wall coordinate u of the point ``along`` metres into wall ``wall`` (0=S,1=W,2=N,3=E)."""
        starts = (0.0, self.width, self.width + self.depth, 2 * self.width + self.depth)
        return starts[wall] + along

    def wall_length(self, wall: int) -> float:
        return self.width if wall % 2 == 0 else self.depth

    def place_wall(self, u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        x, y, nx, ny = self.wall_xy(u)
        return _stack(x, y, self.height - v), _stack(nx, ny, 0.0)

    def floor(self, albedo: Texture) -> Surface:
        """The floor (z = 0, facing up) covered by ``albedo`` (rows, cols) in [0, 1]."""
        return Surface(albedo, (self.width, self.depth), self.place_plane(0.0, 1.0))

    def place_plane(self, z: float, nz: float) -> Placement:
        """Floor (z = 0, nz = 1) or ceiling placement: u = x, v = depth - y."""

        def place(u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
            x, y = np.asarray(u, np.float64), self.depth - np.asarray(v, np.float64)
            return _stack(x, y, z), _stack(0.0 * x, 0.0 * y, nz)

        return place

    def plane_uv(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        return x, self.depth - y


@dataclass(frozen=True)
class Window:
    """A window opening in a wall: wall index (0=S,1=W,2=N,3=E), span along it, z range."""

    wall: int
    along: tuple[float, float]
    z: tuple[float, float]

    def emitters(self, room: Room, n: int = 3) -> tuple[FloatArray, FloatArray]:
        """A grid of n x n points on the opening (n*n, 3) and its inward normal (3,)."""
        a = np.linspace(self.along[0], self.along[1], 2 * n + 1)[1::2]
        z = np.linspace(self.z[0], self.z[1], 2 * n + 1)[1::2]
        x, y, nx, ny = room.wall_xy(np.array([room.wall_u(self.wall, v) for v in a]))
        pts = _stack(np.repeat(x, n), np.repeat(y, n), np.tile(z, n))
        return pts, np.array([float(nx[0]), float(ny[0]), 0.0])

    def passes(self, room: Room, points: FloatArray, direction: FloatArray) -> NDArray[np.bool_]:
        """Whether rays from ``points`` (..., 3) along ``direction`` (3,) leave through it."""
        axis = 1 if self.wall % 2 == 0 else 0
        plane = {0: 0.0, 1: 0.0, 2: room.depth, 3: room.width}[self.wall]
        t = (plane - points[..., axis]) / _nonzero(np.asarray(direction[axis]))
        hit = points + t[..., None] * direction
        x, y = room.wall_xy(np.array([room.wall_u(self.wall, v) for v in self.along]))[:2]
        lateral = hit[..., 1 - axis]
        ends = (x, y)[1 - axis]
        lo, hi = float(min(ends)), float(max(ends))
        return (
            (t > 0)
            & (lateral >= lo)
            & (lateral <= hi)
            & (hit[..., 2] >= self.z[0])
            & (hit[..., 2] <= self.z[1])
        )


@dataclass(frozen=True)
class LightBar:
    """A fluorescent light bar on the ceiling: centre (x, y), length along ``angle``."""

    centre: tuple[float, float]
    length: float
    angle: float

    def emitters(self, height: float, n: int = 3) -> FloatArray:
        """n points along the bar at the ceiling, (n, 3)."""
        t = (np.arange(n) + 0.5) / n - 0.5
        x = self.centre[0] + t * self.length * np.cos(self.angle)
        y = self.centre[1] + t * self.length * np.sin(self.angle)
        return _stack(x, y, height)


@dataclass(eq=False)
class Patch:
    """A rectangle ``x`` x ``y`` (metres) of the floor with its own texture, drawn over the
    floor (and over earlier patches): detail where the cameras look closely, a coarse floor
    elsewhere. Texture coordinates as the floor's, from the patch's corner: u = x - x[0],
    v = y[1] - y."""

    x: tuple[float, float]
    y: tuple[float, float]
    surface: Surface = field(init=False)
    albedo: InitVar[Texture]

    def __post_init__(self, albedo: Texture) -> None:
        (x0, x1), (y0, y1) = self.x, self.y

        def place(u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
            x, y = x0 + np.asarray(u, np.float64), y1 - np.asarray(v, np.float64)
            return _stack(x, y, 0.0), _stack(0.0 * x, 0.0 * y, 1.0)

        self.surface = Surface(albedo, (x1 - x0, y1 - y0), place)

    def contains(self, x: FloatArray, y: FloatArray) -> NDArray[np.bool_]:
        return (x >= self.x[0]) & (x <= self.x[1]) & (y >= self.y[0]) & (y <= self.y[1])

    def uv(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        return x - self.x[0], self.y[1] - y


@dataclass(eq=False)
class Scene:
    """Everything that is drawn: the room's three surfaces, objects, windows, light bars and
    floor patches."""

    room: Room
    wall: Surface
    floor: Surface
    ceiling: Surface
    objects: list[Prism]
    windows: list[Window]
    bars: list[LightBar]
    patches: list[Patch] = field(default_factory=list)

    def room_surfaces(self) -> list[Surface]:
        """Wall, floor, ceiling and the floor patches' surfaces, in atlas order."""
        return [self.wall, self.floor, self.ceiling, *(p.surface for p in self.patches)]

    def surfaces(self) -> list[Surface]:
        """All surfaces in atlas order: :meth:`room_surfaces`, then (side, top, bottom) of each
        object."""
        out = self.room_surfaces()
        for obj in self.objects:
            out.extend(obj.surfaces())
        return out

    def with_objects(self, extra: list[Prism]) -> Scene:
        """The same scene with ``extra`` objects appended (the base is not modified)."""
        return Scene(
            self.room,
            self.wall,
            self.floor,
            self.ceiling,
            [*self.objects, *extra],
            self.windows,
            self.bars,
            self.patches,
        )

    def clearance(self, x: float, y: float, z: float) -> float:
        """Distance from a point to the nearest object, metres (inf with no objects)."""
        return min((o.clearance(x, y, z) for o in self.objects), default=float("inf"))
