"""The outdoor place (style ``outdoor``): a campus square or park edge under the open sky.

The capture grid stands on a paved square (pavers in running or stack bond, kerbs) or on the
lawn beside it; gravel or asphalt paths lead away across the grass. Around the grid stand trees
(trunks and crowns of stacked cylinders, round or conical), benches, litter bins, lamp posts, a
row of bollards, a low wall or a hedge, and one or two buildings 15-30 m off. The place's box
(400 x 400 x 150 m) carries the far scenery — hills, clusters of far buildings and a tree line
against the sky — and the sky itself, which glows: brighter round the sun, with clouds. Far
scenery and sky are painted as seen from the middle of the place on walls 200 m away, so they
shift by under 2 deg across the grid (the real sky would not shift at all).

Light: the sky lights every surface by how much of it the surface faces (no ambient
occlusion); the sun lights every surface facing it, and objects cast sharp sun shadows (the
variants' plant and chairs too). The clouds belong to the place: every variant shows the same
clouds, with its own contrast.

Variants: ``original`` (hazy sun 38 deg up: soft contrast, a bright sky with some clouds, the
sun's disc in view), ``arboreal`` and ``chairs`` (objects added, same light), ``day`` (clear
midday: the sun 62 deg up and 130 deg round from the original's, strong sunlit / shaded
contrast, a darker clear sky with cumulus), ``twilight`` (dusk: the sun 5 deg below the
horizon, dim light from the sky alone, which glows where the sun set), ``winlit`` (its outdoor
analogue: an overcast sky — flat light without sun or shadows, brightest at the zenith, faint
clouds).
"""

from __future__ import annotations

import numpy as np

from homebench.data.synth import outdoor_textures as ot
from homebench.data.synth.layout import GRID_MARGIN, FloorPlanner, legs
from homebench.data.synth.lighting import Lighting, Sky
from homebench.data.synth.outdoor_textures import Backdrop, Ground
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    Box,
    Cylinder,
    Patch,
    Placement,
    Prism,
    Room,
    Scene,
    Surface,
)
from homebench.data.synth.spec import Variant
from homebench.geometry import Grid

#: The cast panorama's pixel at the default image size (360 unfolded columns, 4 x
#: supersampled): each texture holds about one texel per such pixel at the nearest camera.
PIXEL = np.radians(0.25)
#: Ground patches round the grid: (margin beyond the grid, metres; texels per metre). A camera
#: 1 m up sees the ground 0.84 m off at -50 deg, where a pixel covers about a centimetre; the
#: needed density falls with the squared distance, so beyond 4 m the near patch is sampled at
#: its coarsest mip level (1/8) anyway and a patch of that density takes over, then, beyond
#: 25 m, the floor at 1/8 of that again (a 400 m floor at 100 texels/m would take 6 GB).
GROUND = ((4.0, TEXELS_PER_METRE), (25.0, TEXELS_PER_METRE / 8))
_EYE = 1.0  # nominal camera height for texture densities, metres
_ATTEMPTS = 200


def _open_sky(ambient: float, sky: Sky) -> Lighting:
    """Light under ``sky`` alone, ``ambient`` for the light objects reflect onto each other."""
    return Lighting(ambient, 0.0, 0.0, 0.0, 0.0, 0.0, False, sky)


# Sky(luminance at the horizon, zenith / horizon, aureole, cloud contrast, sun irradiance,
#     sun elevation deg, sun azimuth deg from the world's seeded one)
_HAZY = _open_sky(100.0, Sky(2200.0, 1.4, 1.5, 0.6, 2500.0, 38.0, 0.0))
#: Light of each variant (radiance units, see ``lighting.py``).
LIGHTINGS: dict[Variant, Lighting] = {
    "original": _HAZY,
    "arboreal": _HAZY,
    "chairs": _HAZY,
    "day": _open_sky(250.0, Sky(1600.0, 0.6, 3.0, 1.0, 8000.0, 62.0, 130.0)),
    "twilight": _open_sky(0.5, Sky(28.0, 0.5, 4.0, 0.4, 0.0, -5.0, -60.0)),
    "winlit": _open_sky(60.0, Sky(900.0, 3.0, 0.0, 0.25, 0.0, 45.0, 0.0)),
}


def _density(distance: float, rise: float = 0.0) -> float:
    """Texels per metre for a surface ``distance`` metres from the nearest camera (horizontal)
    and ``rise`` metres above or below it: one texel per cast pixel there."""
    d = float(np.hypot(max(distance, 0.3), rise))
    return float(np.clip(1.0 / (d * PIXEL), 1.0, TEXELS_PER_METRE))


class Yard(FloorPlanner):
    """A floor planner for open ground: spots at a chosen distance from the capture grid."""

    def __init__(self, rng: np.random.Generator, room: Room, grid_box: tuple[float, ...]):
        x0, y0, x1, y1 = grid_box
        m = GRID_MARGIN
        super().__init__(rng, room, (x0 - m, y0 - m, x1 + m, y1 + m))
        self.grid_box = grid_box

    def distance(self, x: float, y: float) -> float:
        """Horizontal distance from (x, y) to the nearest camera position's rectangle."""
        x0, y0, x1, y1 = self.grid_box
        return float(np.hypot(max(x0 - x, 0.0, x - x1), max(y0 - y, 0.0, y - y1)))

    def around(self, radius: float, reach: tuple[float, float]) -> tuple[float, float] | None:
        """A free spot (x, y) for a disc of ``radius`` whose edge is ``reach`` metres from the
        grid (near, far), or None; the disc is taken."""
        x0, y0, x1, y1 = self.grid_box
        far = reach[1] + radius
        for _ in range(_ATTEMPTS):
            x = float(self.rng.uniform(x0 - far, x1 + far))
            y = float(self.rng.uniform(y0 - far, y1 + far))
            gap = self.distance(x, y) - radius
            if reach[0] <= gap <= reach[1] and self.free(x, y, radius):
                self.discs.append((x, y, radius))
                return x, y
        return None

    def take_line(self, a: tuple[float, float], b: tuple[float, float], radius: float) -> bool:
        """Take a chain of discs of ``radius`` along the segment a-b if all are free."""
        n = max(2, int(np.ceil(np.hypot(b[0] - a[0], b[1] - a[1]) / radius)) + 1)
        discs = [(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])) for t in np.linspace(0, 1, n)]
        if not all(self.free(x, y, radius) for x, y in discs):
            return False
        self.discs += [(x, y, radius) for x, y in discs]
        return True


def _cap(grey: float) -> np.ndarray:
    """A plain 2 x 2 texture for caps seen from afar or not at all (roofs, trunk tops)."""
    return np.full((2, 2), grey, np.float32)


# --------------------------------------------------------------------------- objects


def _tree(rng: np.random.Generator, yard: Yard, k: int, reach: tuple[float, float]) -> list[Prism]:
    """A trunk and a crown of 6-9 stacked cylinders, round or conical."""
    conifer = rng.random() < 0.3
    radius = float(rng.uniform(1.0, 2.2) if conifer else rng.uniform(1.3, 3.5))
    base = float(rng.uniform(0.4, 1.5) if conifer else rng.uniform(1.8, 3.2))
    height = float(rng.uniform(5.0, 10.0) if conifer else rng.uniform(3.0, 7.0))
    spot = yard.around(radius, reach)
    if spot is None:
        return []
    x, y = spot
    gap = yard.distance(x, y)
    trunk_r = float(rng.uniform(0.1, 0.25))
    top = base + 0.6 * height
    density = _density(gap - trunk_r)
    name = f"tree_{k}"
    parts: list[Prism] = [
        Cylinder(
            f"{name}/trunk",
            0.0,
            top,
            ot.bark(rng, (2 * np.pi * trunk_r, top), density),
            _cap(0.3),
            centre=(x, y),
            radius=trunk_r,
        )
    ]
    n = int(rng.integers(6, 10))
    edges = base + height * np.linspace(0.0, 1.0, n + 1)
    for i in range(n):
        mid = (i + 0.5) / n  # 0 at the crown's base, 1 at its top
        shape = 1.0 - mid if conifer else np.sqrt(1.0 - (2 * mid - 1.0) ** 2)
        r = radius * max(float(shape) * float(rng.uniform(0.85, 1.1)), 0.2)
        off = rng.uniform(-0.12, 0.12, size=2) * (radius - r)
        density = _density(gap - r, edges[i] - _EYE)
        z = (float(edges[i]), float(edges[i + 1]))
        parts.append(
            Cylinder(
                f"{name}/crown_{i}",
                *z,
                ot.foliage(rng, (2 * np.pi * r, z[1] - z[0]), density),
                ot.foliage(rng, (2 * r, 2 * r), density),
                centre=(x + float(off[0]), y + float(off[1])),
                radius=r,
            )
        )
    return parts


def _bench(rng: np.random.Generator, yard: Yard, k: int) -> list[Prism]:
    """Slatted seat and backrest on four legs, its back to the grid."""
    length, depth = float(rng.uniform(1.5, 2.0)), float(rng.uniform(0.45, 0.55))
    seat = float(rng.uniform(0.42, 0.46))
    spot = yard.around(float(np.hypot(length, depth)) / 2 + 0.05, (1.0, 8.0))
    if spot is None:
        return []
    x, y = spot
    x0, y0, x1, y1 = yard.grid_box
    away = np.arctan2(y - (y0 + y1) / 2, x - (x0 + x1) / 2)  # from the grid to the bench
    angle = float(away - np.pi / 2 + rng.normal(0.0, 0.3))  # local +y (the back) points away
    density = _density(yard.distance(x, y) - depth)
    name = f"bench_{k}"
    parts: list[Prism] = [
        Box(
            f"{name}/seat",
            seat - 0.05,
            seat,
            ot.wood_slats(rng, (2 * (length + depth), 0.05), density, 0.1),
            ot.wood_slats(rng, (length, depth), density, 0.1),
            centre=(x, y),
            size=(length, depth),
            angle=angle,
        )
    ]
    ca, sa = np.cos(angle), np.sin(angle)
    ly = depth / 2 - 0.03
    parts.append(
        Box(
            f"{name}/back",
            seat + 0.08,
            seat + 0.45,
            ot.wood_slats(rng, (2 * (length + 0.05), 0.37), density, 0.12),
            _cap(0.4),
            centre=(x - ly * sa, y + ly * ca),
            size=(length, 0.05),
            angle=angle,
        )
    )
    return parts + legs(rng, name, (x, y), (length, depth), angle, seat - 0.05)


def _bin(rng: np.random.Generator, yard: Yard, k: int) -> list[Prism]:
    radius, height = float(rng.uniform(0.2, 0.3)), float(rng.uniform(0.8, 1.0))
    spot = yard.around(radius, (0.5, 12.0))
    if spot is None:
        return []
    density = _density(yard.distance(*spot) - radius)
    grey = float(rng.uniform(0.15, 0.6))
    return [
        Cylinder(
            f"bin_{k}",
            0.0,
            height,
            ot.metal(rng, (2 * np.pi * radius, height), density, grey),
            ot.metal(rng, (2 * radius, 2 * radius), density, 0.1),
            centre=spot,
            radius=radius,
        )
    ]


def _lamp(rng: np.random.Generator, yard: Yard, k: int) -> list[Prism]:
    """A pole with a lantern on top."""
    pole_r, height = float(rng.uniform(0.05, 0.08)), float(rng.uniform(3.5, 5.5))
    head_r = float(rng.uniform(0.18, 0.3))
    spot = yard.around(head_r, (1.5, 18.0))
    if spot is None:
        return []
    density = _density(yard.distance(*spot) - head_r)
    grey = float(rng.uniform(0.15, 0.4))
    return [
        Cylinder(
            f"lamp_{k}/pole",
            0.0,
            height,
            ot.metal(rng, (2 * np.pi * pole_r, height), density, grey),
            _cap(grey),
            centre=spot,
            radius=pole_r,
        ),
        Cylinder(
            f"lamp_{k}/lantern",
            height,
            height + 0.4,
            ot.metal(rng, (2 * np.pi * head_r, 0.4), density, float(rng.uniform(0.5, 0.9))),
            _cap(0.8),
            centre=spot,
            radius=head_r,
        ),
    ]


def _side_line(
    rng: np.random.Generator, yard: Yard, distance: tuple[float, float], length: float
) -> tuple[tuple[float, float], tuple[float, float], float]:
    """A segment of ``length`` parallel to a random side of the grid, ``distance`` (range)
    metres outside it: its ends and the outward angle of that side."""
    x0, y0, x1, y1 = yard.grid_box
    side = int(rng.integers(4))
    d = float(rng.uniform(*distance))
    normal = side * np.pi / 2  # 0: +x side, 1: +y, 2: -x, 3: -y
    nx, ny = np.cos(normal), np.sin(normal)
    cx = (x0 + x1) / 2 + nx * ((x1 - x0) / 2 + d)
    cy = (y0 + y1) / 2 + ny * ((y1 - y0) / 2 + d)
    shift = float(rng.uniform(-0.5, 0.5)) * length
    tx, ty = -ny, nx
    a = (cx + tx * (shift - length / 2), cy + ty * (shift - length / 2))
    b = (cx + tx * (shift + length / 2), cy + ty * (shift + length / 2))
    return a, b, normal


def _bollards(rng: np.random.Generator, yard: Yard) -> list[Prism]:
    """A row of 4-9 bollards along a side of the grid."""
    n, pitch = int(rng.integers(4, 10)), float(rng.uniform(1.2, 2.0))
    radius, height = float(rng.uniform(0.07, 0.12)), float(rng.uniform(0.7, 1.0))
    a, b, _ = _side_line(rng, yard, (1.0, 5.0), (n - 1) * pitch)
    grey = float(rng.uniform(0.15, 0.5))
    out: list[Prism] = []
    for i, t in enumerate(np.linspace(0.0, 1.0, n)):
        x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
        if not yard.free(x, y, radius + 0.05):
            continue
        yard.discs.append((x, y, radius + 0.05))
        density = _density(yard.distance(x, y) - radius)
        out.append(
            Cylinder(
                f"bollard_{i}",
                0.0,
                height,
                ot.metal(rng, (2 * np.pi * radius, height), density, grey),
                ot.metal(rng, (2 * radius, 2 * radius), density, grey),
                centre=(x, y),
                radius=radius,
            )
        )
    return out


def _boundary(rng: np.random.Generator, yard: Yard, k: int) -> list[Prism]:
    """A low wall or a hedge, 4-12 m long, parallel to a side of the grid."""
    hedge = rng.random() < 0.5
    length = float(rng.uniform(4.0, 12.0))
    thick = float(rng.uniform(0.6, 1.2) if hedge else rng.uniform(0.25, 0.5))
    height = float(rng.uniform(0.8, 1.6) if hedge else rng.uniform(0.45, 1.1))
    a, b, normal = _side_line(rng, yard, (2.0, 10.0), length)
    if not yard.take_line(a, b, thick / 2 + 0.05):
        return []
    x, y = (a[0] + b[0]) / 2, (a[1] + b[1]) / 2
    density = _density(yard.distance(x, y) - length / 2)
    perimeter = (2 * (length + thick), height)
    if hedge:
        side, cap = ot.foliage(rng, perimeter, density), ot.foliage(rng, (length, thick), density)
    else:
        side = ot.masonry(rng, perimeter, density)
        cap = ot.metal(rng, (length, thick), density, float(rng.uniform(0.5, 0.8)))
    kind = "hedge" if hedge else "wall"
    return [
        Box(
            f"{kind}_{k}",
            0.0,
            height,
            side,
            cap,
            centre=(x, y),
            size=(length, thick),
            angle=float(normal + np.pi / 2),
        )
    ]


def _building(rng: np.random.Generator, yard: Yard, k: int) -> list[Prism]:
    """A building 15-30 m off, its front to the grid."""
    width, depth = float(rng.uniform(15.0, 40.0)), float(rng.uniform(8.0, 15.0))
    height = float(rng.uniform(6.0, 18.0))
    a, b, normal = _side_line(rng, yard, (15.0, 30.0), width)  # the front's ends
    back = depth / 2 * np.array([np.cos(normal), np.sin(normal)])
    mid_a, mid_b = tuple(np.add(a, back)), tuple(np.add(b, back))
    if not yard.take_line(mid_a, mid_b, depth / 2 * 1.05):
        return []
    density = _density(min(yard.distance(*a), yard.distance(*b)))
    centre = tuple(np.add(a, b) / 2 + back)
    faces = (width, depth, width, depth)
    return [
        Box(
            f"building_{k}",
            0.0,
            height,
            ot.facade(rng, faces, height, density),
            _cap(0.3),
            centre=centre,
            size=(width, depth),
            angle=float(normal + np.pi / 2),
        )
    ]


# --------------------------------------------------------------------------- surfaces


def _ground(ground: Ground, room: Room, box: tuple[float, ...]) -> tuple[Surface, list[Patch]]:
    """The coarse floor of the whole box and the patches of :data:`GROUND`, coarse to fine."""
    floor_density = GROUND[-1][1] / 8
    floor = room.floor(_ground_albedo(ground, (0.0, room.width), (0.0, room.depth), floor_density))
    patches = []
    x0, y0, x1, y1 = box
    for margin, density in reversed(GROUND):
        xs = (max(x0 - margin, 0.0), min(x1 + margin, room.width))
        ys = (max(y0 - margin, 0.0), min(y1 + margin, room.depth))
        patches.append(Patch(xs, ys, _ground_albedo(ground, xs, ys, density)))
    return floor, patches


def _ground_albedo(
    ground: Ground, xs: tuple[float, float], ys: tuple[float, float], density: float
) -> np.ndarray:
    """The ground's albedo over xs x ys at ``density``, rows from ys[1] down (floor layout)."""
    size = (xs[1] - xs[0], ys[1] - ys[0])
    u, v = ot.texel_centres(size, ot.shape_of(size, density))
    return ground.albedo(xs[0] + u, ys[1] - v, density)


def _sky_surface(
    backdrop: Backdrop, room: Room, size: tuple[float, float], place: Placement, density: float
) -> Surface:
    """A surface of the box painted with the backdrop as seen from the middle of the floor."""
    u, v = ot.texel_centres(size, ot.shape_of(size, density))
    points, _ = place(u, v)
    directions = points - np.array([room.width / 2, room.depth / 2, 0.0])
    distance = np.linalg.norm(directions, axis=-1, keepdims=True)
    albedo, glow = backdrop.paint(directions / distance, density * distance[..., 0])
    return Surface(albedo, size, place, glow=glow, glow_kind="sky")


def build(seed: int, room: Room, grid: Grid) -> Scene:
    """The seeded outdoor place without any variant additions."""
    rng = np.random.default_rng([seed, 0])
    (gx0, gy0), (gx1, gy1) = grid.position(0, 0), grid.position(*(n - 1 for n in grid.shape))
    box = (float(gx0), float(gy0), float(gx1), float(gy1))
    yard = Yard(rng, room, box)
    lawn = rng.random() < 0.35  # the grid on the lawn beside the square, else on the square
    margins = rng.uniform(1.5, 8.0, size=4)
    plaza = (box[0] - margins[0], box[1] - margins[1], box[2] + margins[2], box[3] + margins[3])
    if lawn:
        shift = rng.choice([-1.0, 1.0]) * (box[2] - box[0] + margins[0] + margins[2] + 2.0)
        plaza = (plaza[0] + shift, plaza[1], plaza[2] + shift, plaza[3])
    ground = Ground.random(rng, plaza)
    objects: list[Prism] = []
    for k in range(int(rng.integers(1, 3))):
        objects += _building(rng, yard, k)
    for k in range(int(rng.integers(1, 3))):
        objects += _boundary(rng, yard, k)
    n_trees = int(rng.integers(5, 11))
    for k in range(n_trees):
        reach = (2.0, 8.0) if k < 2 else (4.0, 35.0)
        objects += _tree(rng, yard, k, reach)
    for k in range(int(rng.integers(2, 6))):
        objects += _lamp(rng, yard, k)
    for k in range(int(rng.integers(2, 5))):
        objects += _bench(rng, yard, k)
    for k in range(int(rng.integers(1, 4))):
        objects += _bin(rng, yard, k)
    objects += _bollards(rng, yard)
    floor, patches = _ground(ground, room, box)
    backdrop = Backdrop.random(rng)
    near_wall = min(box[0], box[1], room.width - box[2], room.depth - box[3])
    wall = _sky_surface(
        backdrop, room, (room.perimeter, room.height), room.place_wall, _density(near_wall)
    )
    ceiling = _sky_surface(
        backdrop,
        room,
        (room.width, room.depth),
        room.place_plane(room.height, -1.0),
        _density((room.height - _EYE) * np.sqrt(2.0)),
    )
    low = [o for o in objects if o.z1 < room.height]  # a low box: nothing through the sky
    return Scene(room, wall, floor, ceiling, low, [], [], patches)
