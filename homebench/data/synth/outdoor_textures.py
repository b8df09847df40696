"""Procedural textures of outdoor places, painted at any density (texels per metre).

Sizes are metres. Every painter takes the density it paints at and leaves out detail finer than
about two texels (the texture's mip levels would average it away anyway), so a far object gets
a small texture with the right local statistics. The ground is a function of world position
(:class:`Ground`): the detailed patch round the cameras and the coarse ground beyond show the
same pavers and lawns. The far scenery and the sky are functions of the direction seen from
the middle of the place (:class:`Backdrop`). Albedo in [0, 1], float32, row 0 at the top.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.data.synth.textures import Texture

Rng = np.random.Generator
FloatArray = NDArray[np.float64]
_TABLE = 128  # side of a noise lattice table, cells
_OCTAVES = 8  # most octaves a noise field may have


def texel_centres(size: tuple[float, float], shape: tuple[int, int]) -> tuple[FloatArray, ...]:
    """(u, v) in metres of the texel centres of a texture of ``shape`` (rows, cols) covering
    ``size`` (u, v): u (1, cols), v (rows, 1)."""
    rows, cols = shape
    u = (np.arange(cols) + 0.5) / cols * size[0]
    v = (np.arange(rows) + 0.5) / rows * size[1]
    return u[None, :], v[:, None]


def shape_of(size: tuple[float, float], density: float) -> tuple[int, int]:
    """(rows, cols) of a texture covering ``size`` (u, v) metres at ``density``."""
    return max(2, int(np.ceil(size[1] * density))), max(2, int(np.ceil(size[0] * density)))


def _fade(texels: FloatArray | float) -> FloatArray:
    """Weight of a detail spanning ``texels`` texels: 1 from 3 texels, 0 below 1.5."""
    return np.clip((np.asarray(texels) - 1.5) / 1.5, 0.0, 1.0)


@lru_cache(maxsize=1)
def _tables() -> tuple[NDArray[np.float32], ...]:
    """The random lattices all noise fields sample, one per octave (fixed: fields differ by
    their seeded offsets)."""
    rng = np.random.default_rng(0x5EED)
    return tuple(rng.standard_normal((_TABLE, _TABLE)).astype(np.float32) for _ in range(_OCTAVES))


def _coarse(axis: FloatArray, step: int) -> FloatArray:
    """Where the samples of a regular axis (n,) thinned ``step`` times lie so that
    ``cv2.resize`` stretches them back onto the axis exactly."""
    n = axis.size
    m = -(-n // step)
    index = (np.arange(m) + 0.5) * n / m - 0.5
    return axis[0] + index * (axis[-1] - axis[0]) / max(n - 1, 1)


class Noise:
    """Smooth fractal value noise fixed in world coordinates (metres): octaves of ``cell``,
    cell / 2, ... with weights 1, p, p^2, ... (p: ``persistence``), each at a seeded offset.
    ``turn`` turns each octave by its own angle (no grid-aligned blocks); unturned fields are
    fast on regular grids."""

    def __init__(
        self,
        rng: Rng,
        cell: float,
        octaves: int = 4,
        persistence: float = 0.5,
        turn: bool = True,
    ):
        self.cell, self.octaves, self.persistence, self.turn = cell, octaves, persistence, turn
        self.offsets = rng.uniform(0.0, _TABLE, size=(octaves, 2))

    def __call__(self, x: FloatArray, y: FloatArray, density: FloatArray | float) -> Texture:
        """The field at world points (x, y) (broadcast to 2-D); octaves finer than about two
        texels at ``density`` (texels per metre, scalar or per point) fade out. Zero mean,
        about unit standard deviation with every octave present."""
        x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
        shape = np.broadcast_shapes(x.shape, y.shape)
        grid = x.shape == (1, shape[1]) and y.shape == (shape[0], 1) and np.ndim(density) == 0
        out = np.zeros(shape, np.float32)
        total = 0.0
        for k in range(self.octaves):
            c, w = self.cell / 2**k, self.persistence**k
            total += w * w
            weight = (w * _fade(c * np.asarray(density))).astype(np.float32)
            if not np.any(weight > 0):
                continue
            if self.turn or not grid:
                sample = self._octave(k, x, y, c)
            else:
                step = max(1, int(c * float(density) / 4))  # four samples per cell suffice
                small = self._octave(
                    k, _coarse(x[0], step)[None, :], _coarse(y[:, 0], step)[:, None], c
                )
                sample = cv2.resize(small, (shape[1], shape[0]), interpolation=cv2.INTER_LINEAR)
            out += weight * sample
        return out / np.float32(np.sqrt(total) * 0.8)  # cubic lookups lose about 20 % of std

    def _octave(self, k: int, x: FloatArray, y: FloatArray, c: float) -> Texture:
        """Octave ``k`` (cell ``c``) at (x, y), broadcast to 2-D."""
        ox, oy = self.offsets[k]
        if self.turn:
            ca, sa = np.cos(0.7 * k) / c, np.sin(0.7 * k) / c
            x, y = x * ca + y * sa, y * ca - x * sa
        else:
            x, y = x / c, y / c
        shape = np.broadcast_shapes(x.shape, y.shape)
        mx = np.broadcast_to(np.mod(x + ox, _TABLE), shape)
        my = np.broadcast_to(np.mod(y + oy, _TABLE), shape)
        return cv2.remap(
            _tables()[k],
            np.ascontiguousarray(mx, np.float32),
            np.ascontiguousarray(my, np.float32),
            cv2.INTER_CUBIC,
            borderMode=cv2.BORDER_WRAP,
        )


def _band(e: FloatArray, half: float, h: FloatArray | float) -> FloatArray:
    """Box-filtered coverage of the band |e| <= ``half`` by texels of half-width ``h``
    centred at distances ``e`` >= 0 from the band's middle."""
    return np.clip(np.minimum(e + h, half) - np.maximum(e - h, -half), 0.0, None) / (2 * h)


def _inside(d: FloatArray, h: FloatArray | float) -> FloatArray:
    """Box-filtered coverage of the region d >= 0 (d: signed distance into it, metres)."""
    return np.clip(d / (2 * h) + 0.5, 0.0, 1.0)


def bond(
    u: FloatArray,
    v: FloatArray,
    unit: tuple[float, float],
    offset: float,
    joint: float,
    density: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Pavers or bricks laid in rows along u: (row, column) index of the unit at each point and
    the box-filtered coverage of the joints. ``unit`` (along u, along v) metres; ``offset``:
    shift of each row as a fraction of a unit (0.5 running bond, 0 stack bond)."""
    h = 0.5 / density
    row = np.floor(v / unit[1])
    shifted = u + offset * unit[0] * row
    col = np.floor(shifted / unit[0])
    eu = np.abs(shifted - (col + 0.5) * unit[0])
    ev = np.abs(v - (row + 0.5) * unit[1])
    cu = _band(unit[0] / 2 - eu, joint / 2, h)
    cv = _band(unit[1] / 2 - ev, joint / 2, h)
    return row, col, cu + cv - cu * cv


def stripes(v: FloatArray, pitch: float, gap: float, density: float) -> FloatArray:
    """Box-filtered coverage of gaps of ``gap`` metres every ``pitch`` metres along v."""
    e = np.abs(np.mod(v, pitch) - pitch / 2)
    return _band(pitch / 2 - e, gap / 2, 0.5 / density)


def fill(
    tex: Texture,
    density: float,
    u: tuple[float, float],
    v: tuple[float, float],
    value: float,
) -> None:
    """Blend ``value`` into the rectangle ``u`` x ``v`` (metres) of ``tex`` with box-filtered
    (anti-aliased) edges."""
    rows, cols = tex.shape
    c0, c1 = max(int(u[0] * density) - 1, 0), min(int(u[1] * density) + 2, cols)
    r0, r1 = max(int(v[0] * density) - 1, 0), min(int(v[1] * density) + 2, rows)
    if c1 <= c0 or r1 <= r0:
        return
    h = 0.5 / density
    cu = (np.arange(c0, c1) + 0.5) / density
    cv = (np.arange(r0, r1) + 0.5) / density
    wu = _inside(np.minimum(cu - u[0], u[1] - cu), h)
    wv = _inside(np.minimum(cv - v[0], v[1] - cv), h)
    w = (wv[:, None] * wu[None, :]).astype(np.float32)
    block = tex[r0:r1, c0:c1]
    block += w * (np.float32(value) - block)


# --------------------------------------------------------------------------- materials


def foliage(rng: Rng, size: tuple[float, float], density: float) -> Texture:
    """Tree crowns and hedges: clumps of leaves, lit and shaded, with dark gaps between."""
    u, v = texel_centres(size, shape_of(size, density))
    clumps = Noise(rng, 0.6, 3)(u, v, density)
    leaves = Noise(rng, 0.06, 2, 0.7)(u, v, density)
    tex = 0.2 + 0.07 * clumps + 0.07 * leaves
    gaps = _fade(0.3 * density) * np.clip(-0.8 - clumps, 0.0, 1.0)  # holes show the dark inside
    return np.clip(tex - 0.25 * gaps, 0.02, 1.0).astype(np.float32)


def bark(rng: Rng, size: tuple[float, float], density: float) -> Texture:
    """Bark: dark, with vertical furrows."""
    u, v = texel_centres(size, shape_of(size, density))
    furrows = Noise(rng, 0.05, 2, turn=False)(u, v * 0.15, density)  # cells 7x longer along v
    return (float(rng.uniform(0.2, 0.32)) + 0.06 * furrows).astype(np.float32)


def metal(rng: Rng, size: tuple[float, float], density: float, grey: float) -> Texture:
    """Painted metal of ``grey`` with faint streaks, half of them with a light band at the top."""
    u, v = texel_centres(size, shape_of(size, density))
    tex = (grey + 0.02 * Noise(rng, 0.05, 2, turn=False)(u, v * 0.1, density)).astype(np.float32)
    if rng.random() < 0.5:
        top = float(rng.uniform(0.05, 0.15))
        fill(tex, density, (0.0, size[0]), (top, top + 0.06), float(rng.uniform(0.7, 0.9)))
    return tex


def wood_slats(rng: Rng, size: tuple[float, float], density: float, pitch: float) -> Texture:
    """Boards along u, ``pitch`` metres apart along v, with dark gaps."""
    u, v = texel_centres(size, shape_of(size, density))
    grain = Noise(rng, 0.02, 2, turn=False)(u * 0.1, v, density)
    tex = float(rng.uniform(0.3, 0.55)) + 0.04 * grain
    gaps = stripes(v, pitch, 0.015, density)
    return (tex * (1.0 - gaps) + 0.06 * gaps).astype(np.float32)


def masonry(rng: Rng, size: tuple[float, float], density: float) -> Texture:
    """A wall of stone blocks or bricks in running bond with mortar joints."""
    u, v = texel_centres(size, shape_of(size, density))
    brick = rng.random() < 0.5
    unit = (0.24, 0.075) if brick else (float(rng.uniform(0.35, 0.6)), float(rng.uniform(0.2, 0.3)))
    row, col, joints = bond(u, v, unit, 0.5, 0.012 if brick else 0.02, density)
    shades = rng.normal(0.0, 0.06, size=(64, 64)).astype(np.float32)
    shade = shades[row.astype(np.int64) % 64, col.astype(np.int64) % 64]
    base = float(rng.uniform(0.3, 0.6))
    tex = base + shade * _fade(unit[1] * density) + 0.03 * Noise(rng, 0.3, 3)(u, v, density)
    return (tex * (1.0 - joints) + float(rng.uniform(0.5, 0.75)) * joints).astype(np.float32)


def facade(rng: Rng, faces: tuple[float, ...], height: float, density: float) -> Texture:
    """A building's walls unrolled round it (``faces``: widths, metres, in unrolling order):
    storeys of windows (glass reflecting the sky in random greys, some blinds), a plinth, a
    cornice and an entrance in the middle of the first face."""
    size = (float(sum(faces)), height)
    if rng.random() < 0.4:
        tex = masonry(rng, size, density)
    else:
        u, v = texel_centres(size, shape_of(size, density))
        grey = float(rng.uniform(0.4, 0.75))
        tex = (grey + 0.03 * Noise(rng, 2.0, 3)(u, v, density)).astype(np.float32)
    storey = float(rng.uniform(3.0, 3.6))
    win_w, win_h = float(rng.uniform(0.9, 1.8)), float(rng.uniform(1.3, 1.9))
    pitch = win_w + float(rng.uniform(0.8, 2.2))
    frame = float(rng.uniform(0.6, 0.9))
    fill(tex, density, (0, size[0]), (height - 0.6, height), float(rng.uniform(0.15, 0.35)))
    fill(tex, density, (0, size[0]), (0.0, 0.4), float(rng.uniform(0.5, 0.85)))
    start = 0.0
    for k, width in enumerate(faces):
        n = int((width - 1.0) // pitch)
        margin = (width - n * pitch) / 2
        for floor in range(int((height - 1.0) // storey)):
            sill = height - (floor * storey + 1.0)  # v of the sills, metres from the top
            for i in range(n):
                a = start + margin + i * pitch + (pitch - win_w) / 2
                if k == 0 and floor == 0 and i == n // 2:  # the entrance
                    fill(tex, density, (a - 0.3, a + win_w + 0.3), (height - 2.4, height), 0.12)
                    continue
                outer = (sill - win_h - 0.06, sill)
                fill(tex, density, (a - 0.06, a + win_w + 0.06), outer, frame)
                glass = float(rng.uniform(0.08, 0.45))
                fill(tex, density, (a, a + win_w), (sill - win_h, sill - 0.06), glass)
                if rng.random() < 0.3:  # a blind half down
                    fill(tex, density, (a, a + win_w), (sill - win_h, sill - win_h / 2), 0.7)
        start += width
    return tex


# --------------------------------------------------------------------------- the ground


@dataclass(frozen=True)
class Ground:
    """An outdoor ground as a function of world position (metres): a lawn, a paved square
    ``plaza`` (x0, y0, x1, y1) with kerb stones, and ``paths`` ((x, y, angle, width): strips
    from a point outward)."""

    plaza: tuple[float, float, float, float]
    paths: tuple[tuple[float, float, float, float], ...]
    slab: tuple[float, float]  # paver size along x and y, metres
    offset: float  # shift of each row of pavers, fraction of a paver
    grey: tuple[float, float, float]  # paving, lawn, paths
    shades: NDArray[np.float32]  # per-paver shade offsets (64, 64)
    fields: tuple[Noise, ...]  # lawn patches, grass, paving stains, stone grain, gravel

    @classmethod
    def random(cls, rng: Rng, plaza: tuple[float, float, float, float]) -> Ground:
        """A ground with random pavers, lawn and 1-2 paths leaving ``plaza``'s middle."""
        x0, y0, x1, y1 = plaza
        paths = tuple(
            ((x0 + x1) / 2, (y0 + y1) / 2, float(rng.uniform(0, 2 * np.pi)), float(width))
            for width in rng.uniform(1.5, 3.5, size=int(rng.integers(1, 3)))
        )
        square = bool(rng.random() < 0.4)
        side = float(rng.uniform(0.3, 0.6))
        slab = (side, side) if square else (side, side * float(rng.uniform(0.4, 0.7)))
        paving, lawn, path = (
            float(rng.uniform(*r)) for r in ((0.3, 0.5), (0.17, 0.27), (0.22, 0.45))
        )
        fields = (
            Noise(rng, 6.0, 4, turn=False),
            Noise(rng, 0.1, 3, 0.8, turn=False),
            Noise(rng, 3.0, 3, turn=False),
            Noise(rng, 0.05, 2, turn=False),
            Noise(rng, 0.03, 2, turn=False),
        )
        shades = rng.normal(0.0, 0.045, size=(64, 64)).astype(np.float32)
        offset = 0.0 if square else 0.5
        return cls(plaza, paths, slab, offset, (paving, lawn, path), shades, fields)

    def albedo(self, x: FloatArray, y: FloatArray, density: float) -> Texture:
        """Albedo at world points x (1, cols), y (rows, 1), painted at ``density``."""
        x, y = np.asarray(x, np.float32), np.asarray(y, np.float32)
        h = 0.5 / density
        x0, y0, x1, y1 = self.plaza
        patches, grass, stains, grain, gravel = self.fields
        paving_grey, lawn_grey, path_grey = self.grey
        tex = lawn_grey + 0.025 * patches(x, y, density) + 0.05 * grass(x, y, density)
        for px, py, angle, width in self.paths:
            along = (x - px) * np.cos(angle) + (y - py) * np.sin(angle)
            across = np.abs((y - py) * np.cos(angle) - (x - px) * np.sin(angle))
            cover = _inside(width / 2 - across, h) * (along > 0)
            path = path_grey + 0.04 * gravel(x, y, density)
            edge = _band(width / 2 - across, 0.05, h) * (along > 0)
            tex = tex + cover * (path - tex) + edge * (0.6 - tex)
        row, col, joints = bond(x - x0, y - y0, self.slab, self.offset, 0.008, density)
        shade = self.shades[row.astype(np.int64) % 64, col.astype(np.int64) % 64]
        paving = (
            paving_grey
            + shade * _fade(min(self.slab) * density / 2)
            + 0.05 * stains(x, y, density)
            + 0.04 * grain(x, y, density)
        )
        paving = paving * (1.0 - joints) + 0.2 * joints
        inside = np.minimum(np.minimum(x - x0, x1 - x), np.minimum(y - y0, y1 - y))
        paving = paving + _band(inside - 0.1, 0.1, h) * (0.65 - paving)  # kerb stones
        tex = tex + _inside(inside, h) * (paving - tex)
        return np.clip(tex, 0.0, 1.0).astype(np.float32)


# --------------------------------------------------------------------------- far scenery


@dataclass(frozen=True)
class Backdrop:
    """The far scenery and the sky round an outdoor place, by direction: hills, far buildings
    and a tree line against the sky, clouds above. Profiles are top elevations (rad) at
    :attr:`samples` azimuths (world directions, ccw from +x)."""

    hills: FloatArray
    buildings: FloatArray
    building_grey: FloatArray
    trees: FloatArray
    cloudiness: float  # threshold of the cloud field: higher, fewer clouds
    fields: tuple[Noise, ...]  # hills, tree line, clouds
    samples: ClassVar[int] = 2048

    @classmethod
    def random(cls, rng: Rng) -> Backdrop:
        n = cls.samples
        az = np.arange(n) * 2 * np.pi / n

        def smooth(cells: int) -> FloatArray:
            """Periodic smooth noise round the horizon, about unit std."""
            values = rng.standard_normal(cells)
            knots = np.arange(cells + 1) * 2 * np.pi / cells
            return np.interp(az, knots, np.append(values, values[0]))

        def arc(mid: float, half: float) -> FloatArray:
            """|azimuth - mid| / half."""
            return np.abs(np.angle(np.exp(1j * (az - mid)))) / half

        hills = np.radians(1.5 + 2.0 * np.clip(smooth(9) + 0.5 * smooth(31), -1.0, None))
        buildings, grey = np.zeros(n), np.zeros(n)
        for _ in range(int(rng.integers(1, 4))):  # clusters of far buildings
            centre = rng.uniform(0, 2 * np.pi)
            for _ in range(int(rng.integers(2, 9))):
                on = arc(centre + rng.normal(0.0, 0.15), np.radians(rng.uniform(0.8, 4.0))) < 1
                top = np.radians(rng.uniform(2.0, 9.0))
                nearer = on & (top > buildings)
                buildings[nearer], grey[nearer] = top, rng.uniform(0.3, 0.6)
        crowns = np.zeros(n)
        for _ in range(int(rng.integers(100, 180))):  # the tree line: overlapping round crowns
            d = arc(rng.uniform(0, 2 * np.pi), np.radians(rng.uniform(0.6, 3.0)))
            top = np.radians(rng.uniform(2.0, 7.0))
            crowns = np.maximum(crowns, top * np.sqrt(np.clip(1.0 - d * d, 0.0, None)))
        trees = crowns * (smooth(7) > -0.7)  # gaps in the tree line
        fields = (Noise(rng, 0.5, 3), Noise(rng, 0.4, 3), Noise(rng, 0.6, 5, 0.55))
        return cls(hills, buildings, grey, trees, float(rng.uniform(-0.3, 0.6)), fields)

    def paint(
        self, directions: FloatArray, texels_per_radian: FloatArray
    ) -> tuple[Texture, Texture]:
        """(albedo, sky glow pattern) in unit ``directions`` (rows, cols, 3), painted at
        ``texels_per_radian`` (rows, cols): the far scenery where it stands (glow 0), sky
        elsewhere (albedo 0, glow 1 + the clouds' deviation)."""
        elevation = np.arcsin(np.clip(directions[..., 2], -1.0, 1.0))
        albedo = np.zeros(elevation.shape, np.float32)
        scenery = np.zeros(elevation.shape, bool)
        top = max(self.hills.max(), self.buildings.max(), self.trees.max())
        rows = np.flatnonzero((elevation < top).any(axis=1))
        if rows.size:  # the scenery's rows only (none on a ceiling)
            band = slice(int(rows[0]), int(rows[-1]) + 1)
            albedo[band], scenery[band] = self._scenery(
                directions[band], elevation[band], texels_per_radian[band]
            )
        # clouds: a noise field on a plane above, in perspective; flat near the horizon
        lift = np.maximum(directions[..., 2], np.sin(np.radians(2.0)))
        plane = (directions[..., 0] / lift, directions[..., 1] / lift)
        field = self.fields[2](*plane, texels_per_radian * lift**2)
        cover = np.clip((field - self.cloudiness) / 1.2 + 0.5, 0.0, 1.0)
        cover = cover * cover * (3.0 - 2.0 * cover)  # smoothstep: soft edges
        fade = np.clip(elevation / np.radians(10.0), 0.0, 1.0)
        glow = 1.0 + fade * (0.6 * cover - 0.3)
        return albedo, np.where(scenery, 0.0, glow).astype(np.float32)

    def _scenery(
        self, directions: FloatArray, elevation: FloatArray, texels_per_radian: FloatArray
    ) -> tuple[Texture, NDArray[np.bool_]]:
        """Albedo of the far scenery and where it stands (both (rows, cols))."""
        azimuth = np.arctan2(directions[..., 1], directions[..., 0])
        k = np.rint(np.mod(azimuth, 2 * np.pi) / (2 * np.pi) * self.samples).astype(np.int64)
        k %= self.samples
        s = 30.0  # noise coordinates per radian of the scenery
        a, e, density = azimuth * s, elevation * s, texels_per_radian / s
        hill_noise, tree_noise, _ = self.fields
        layers = (  # far to near: a nearer layer covers a farther one
            (self.hills, 0.5 + 0.03 * hill_noise(a, e, density)),
            (self.buildings, self.building_grey[k]),
            (self.trees, 0.2 + 0.06 * tree_noise(a, e, density)),
        )
        albedo = np.zeros(elevation.shape, np.float32)
        scenery = np.zeros(elevation.shape, bool)
        for profile, grey in layers:
            here = elevation < profile[k]
            albedo = np.where(here, grey, albedo)
            scenery |= here
        return albedo.astype(np.float32), scenery
