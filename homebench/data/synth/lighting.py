"""Light in the room, baked into the textures: radiance = albedo x irradiance + glow.

Sources: a uniform ambient term (inter-reflections), the ceiling's fluorescent bars, the
window(s) as diffuse area lights and, in ``day``, the sun through the window(s) (sun patches).
Indoors no object casts shadows, so an added object changes only the pixels it covers.

Under an open sky (:class:`Sky`, outdoor styles) the sky dome lights every surface by how much
of it the surface faces and the ground (:data:`GROUND_ALBEDO`) reflects light onto what faces
it, both without occlusion (no ambient occlusion); the sun lights every surface
facing it, and every object casts a sharp sun shadow on the floor, the patches and the other
objects (one shadow ray per lightmap point). The box's walls and ceiling stand for the far
scenery and the sky: they take no shadows. Sky surfaces (``glow_kind`` "sky") glow with the
sky's luminance in their direction seen from the middle of the floor: a gradient from the
horizon to the zenith, the aureole round the sun, the sun's disc, and their glow pattern as
clouds.

Irradiance is computed on a coarse grid of each texture (every :data:`LIGHTMAP_STEP` texels)
and upsampled: light varies slowly. Units: radiance of a white (albedo 1) surface, on the scale
where 255 fills the camera's sensor at exposure time 1 (:mod:`homebench.data.synth.camera`).
Each style holds its variants' lighting.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.data.synth.scene import Scene, Surface
from homebench.data.synth.spec import Variant

FloatArray = NDArray[np.float64]
LIGHTMAP_STEP = 4
_MIN_SQUARED_DISTANCE = 0.05
#: Angular radius of the sun's disc as drawn (the true 0.27 deg widened to the cast pixels).
SUN_RADIUS = np.radians(0.5)
#: Luminance of the sun's disc per unit of direct irradiance (saturates any exposure).
SUN_LUMINANCE = 50.0
#: Angular scale of the aureole: its extra luminance falls as exp(-angle / AUREOLE_WIDTH).
AUREOLE_WIDTH = np.radians(15.0)
#: Mean albedo of open ground: the sky's and sun's light it reflects onto surfaces facing
#: sideways or down.
GROUND_ALBEDO = 0.2


@dataclass(frozen=True)
class Sky:
    """An open sky: its light on the scene and its own luminance (radiance units).

    ``sun_azimuth_deg`` is counted from the world's seeded sun azimuth (:func:`sun_direction`),
    so variants move the sun consistently in every world.
    """

    luminance: float  # of a cloudless patch at the horizon, far from the sun
    zenith: float  # luminance at the zenith / at the horizon (overcast about 3, clear below 1)
    aureole: float  # extra luminance towards the sun, relative, at the sun
    clouds: float  # contrast of the clouds (the glow pattern's deviation from 1 is scaled by it)
    sun: float  # direct irradiance on a surface facing the sun (0: no sun, no disc)
    sun_elevation_deg: float
    sun_azimuth_deg: float

    @property
    def irradiance(self) -> float:
        """Irradiance of a horizontal surface from the dome (sun's disc excluded): the
        luminance model integrated over the hemisphere, cos-weighted (the aureole as a patch of
        2 pi w^2 sr at the sun). A surface tilted by t gets about (1 + cos t) / 2 of it."""
        gradient = 1.0 + 2.0 * (self.zenith - 1.0) / 3.0
        rise = max(np.sin(np.radians(self.sun_elevation_deg)), 0.0)
        aureole = self.aureole * 2.0 * AUREOLE_WIDTH**2 * rise * (1.0 + (self.zenith - 1.0) * rise)
        return float(self.luminance * (gradient + aureole))


@dataclass(frozen=True)
class Lighting:
    """One lighting condition (intensities in radiance units of a white surface)."""

    ambient: float
    ceiling: float  # irradiance scale of each light bar
    window: float  # irradiance scale of each window's diffuse light
    sun: float  # irradiance in sun patches through the windows (0: no sun)
    lights_glow: float  # luminance of the light bars' diffusers when on
    window_glow: float  # luminance of the view outside when the curtains are open
    curtains_open: bool
    sky: Sky | None = None  # an open sky above the scene (outdoors)


#: The indoor styles' luminaires on, curtains or blinds shut (their original light).
LIGHTS_ON = Lighting(110.0, 230.0, 0.0, 0.0, 600.0, 0.0, False)


def indoor_lightings(
    day: Lighting, twilight: Lighting, winlit: Lighting, lights_on: Lighting = LIGHTS_ON
) -> dict[Variant, Lighting]:
    """An indoor style's lighting per variant: ``lights_on`` (the luminaires on) for
    ``original`` and the object variants (they change what is there, not the light), and the
    three daylight ones."""
    return {
        "original": lights_on,
        "arboreal": lights_on,
        "chairs": lights_on,
        "day": day,
        "twilight": twilight,
        "winlit": winlit,
    }


def _emitters(
    points: FloatArray, normals: FloatArray, sources: FloatArray, facing: FloatArray
) -> FloatArray:
    """Sum over Lambertian point emitters of cos(surface) cos(emitter) / d^2; shape (...)."""
    out = np.zeros(points.shape[:-1])
    for source in sources:
        w = source - points
        d2 = np.maximum(np.einsum("...k,...k->...", w, w), _MIN_SQUARED_DISTANCE)
        w = w / np.sqrt(d2)[..., None]
        cos_s = np.maximum(np.einsum("...k,...k->...", w, normals), 0.0)
        cos_e = np.maximum(-(w @ facing), 0.0)
        out += cos_s * cos_e / d2
    return out / len(sources)


def _unit(azimuth: float, elevation: float) -> FloatArray:
    ce = np.cos(elevation)
    return np.array([ce * np.cos(azimuth), ce * np.sin(azimuth), np.sin(elevation)])


def sun_direction(scene: Scene, lighting: Lighting, seed: int) -> FloatArray:
    """Unit vector towards the sun (3,), drawn from its own stream ``default_rng([seed, 2])``.

    Under an open sky: at the sky's elevation, its azimuth offset from a seeded azimuth;
    indoors: out through the first window, 25-40 deg up; (0, 0, 1) with neither.
    """
    rng = np.random.default_rng([seed, 2])
    if lighting.sky is not None:
        sky = lighting.sky
        azimuth = rng.uniform(0.0, 2 * np.pi) + np.radians(sky.sun_azimuth_deg)
        return _unit(azimuth, np.radians(sky.sun_elevation_deg))
    if not scene.windows:
        return np.array([0.0, 0.0, 1.0])
    w = scene.windows[0]
    _, inward = w.emitters(scene.room, 1)
    out_angle = np.arctan2(-inward[1], -inward[0]) + rng.uniform(-0.6, 0.6)
    elevation = rng.uniform(np.radians(25), np.radians(40))
    return _unit(out_angle, elevation)


def sky_luminance(sky: Sky, directions: FloatArray, sun: FloatArray) -> FloatArray:
    """Luminance of a cloudless sky in unit ``directions`` (..., 3), the sun's disc included;
    shape (...)."""
    up = np.clip(directions[..., 2], 0.0, 1.0)
    angle = np.arccos(np.clip(directions @ sun, -1.0, 1.0))
    out = sky.luminance * (1.0 + (sky.zenith - 1.0) * up)
    out *= 1.0 + sky.aureole * np.exp(-angle / AUREOLE_WIDTH)
    if sky.sun > 0:
        out += SUN_LUMINANCE * sky.sun * (angle < SUN_RADIUS)
    return out


def _sunlit(scene: Scene, sun: FloatArray, points: FloatArray, facing: FloatArray) -> FloatArray:
    """Sun on points (..., 3) whose normals give ``facing`` = max(n . sun, 0) (...), with the
    objects' shadows; shape (...)."""
    if sun[2] <= 0:
        return np.zeros_like(facing)
    flat_points, flat = points.reshape(-1, 3), facing.reshape(-1).copy()
    lit = np.flatnonzero(flat > 0)
    if lit.size == 0:
        return facing
    lit = lit[np.argsort(flat_points[lit, 0], kind="stable")]  # by x, to slice by x ranges
    xs, ys = flat_points[lit, 0], flat_points[lit, 1]
    bottom = float(flat_points[lit, 2].min())
    run = sun[:2] / sun[2]  # horizontal metres towards the sun per metre up
    # a point is shadowed only if an object's footprint box, shifted back from the sun by the
    # heights its ray climbs inside the object (0 to top - bottom), holds it
    boxes = np.array([obj.bounds for obj in scene.objects]).reshape(-1, 4)
    tops = np.array([obj.z1 for obj in scene.objects])
    climb = np.maximum(tops - bottom, 0.0)[:, None] * run  # (n, 2)
    lo = boxes[:, :2] - np.maximum(climb, 0.0)
    hi = boxes[:, 2:] - np.minimum(climb, 0.0)
    first = np.searchsorted(xs, lo[:, 0])
    last = np.searchsorted(xs, hi[:, 0], side="right")
    maybe = (tops > bottom) & (last > first) & (hi[:, 1] >= ys.min()) & (lo[:, 1] <= ys.max())
    for k in np.flatnonzero(maybe):
        near = lit[first[k] : last[k]]
        y, z = flat_points[near, 1], flat_points[near, 2]
        near = near[(y >= lo[k, 1]) & (y <= hi[k, 1]) & (z < tops[k]) & (flat[near] > 0)]
        if near.size:
            flat[near[scene.objects[k].blocks(flat_points[near], sun)]] = 0.0
    return flat.reshape(facing.shape)


def irradiance(
    scene: Scene,
    lighting: Lighting,
    sun: FloatArray,
    points: FloatArray,
    normals: FloatArray,
    shadows: bool = True,
) -> FloatArray:
    """Irradiance at world points (..., 3) with unit normals (..., 3); shape (...).

    ``shadows`` False: no object shadows the sun under an open sky (the far scenery).
    """
    e = np.full(points.shape[:-1], lighting.ambient)
    if lighting.sky is not None:
        sky = lighting.sky
        up = normals[..., 2]
        e += sky.irradiance * (1.0 + up) / 2.0
        light_on_ground = sky.irradiance + sky.sun * max(float(sun[2]), 0.0)
        e += GROUND_ALBEDO * light_on_ground * (1.0 - up) / 2.0  # light the ground reflects
        if sky.sun > 0:
            facing = np.maximum(normals @ sun, 0.0)
            e += sky.sun * (_sunlit(scene, sun, points, facing) if shadows else facing)
    if lighting.ceiling > 0 and scene.bars:
        sources = np.concatenate([b.emitters(scene.room.height) for b in scene.bars])
        e += (
            lighting.ceiling
            * len(scene.bars)
            * _emitters(points, normals, sources, np.array([0.0, 0.0, -1.0]))
        )
    for window in scene.windows:
        sources, inward = window.emitters(scene.room)
        if lighting.window > 0:
            e += lighting.window * _emitters(points, normals, sources, inward)
        if lighting.sun > 0:
            lit = window.passes(scene.room, points, sun)
            e += lighting.sun * lit * np.maximum(normals @ sun, 0.0)
    return e


def radiance(
    surface: Surface, scene: Scene, lighting: Lighting, sun: FloatArray
) -> NDArray[np.float32]:
    """The surface's texture as seen under ``lighting`` (grey levels, float32, unclipped)."""
    rows, cols = surface.albedo.shape
    coarse = (max(2, -(-rows // LIGHTMAP_STEP)), max(2, -(-cols // LIGHTMAP_STEP)))
    u = (np.arange(coarse[1]) + 0.5) / coarse[1] * surface.size[0]
    v = (np.arange(coarse[0]) + 0.5) / coarse[0] * surface.size[1]
    points, normals = surface.place(u[None, :], v[:, None])
    far = surface is scene.wall or surface is scene.ceiling
    e = irradiance(scene, lighting, sun, points, normals, shadows=not far).astype(np.float32)
    e = cv2.resize(e, (cols, rows), interpolation=cv2.INTER_LINEAR)
    albedo = surface.albedo
    if lighting.curtains_open and surface.albedo_open is not None:
        albedo = surface.albedo_open
    out = albedo * e
    if surface.glow is not None and surface.glow_kind == "sky":
        out = out + _sky_glow(surface, scene, lighting.sky, sun)
    elif surface.glow is not None:
        glow = lighting.lights_glow if surface.glow_kind == "lights" else lighting.window_glow
        if not lighting.curtains_open and surface.glow_kind == "window":
            glow = 0.0
        out = out + glow * surface.glow
    return out.astype(np.float32)


def _sky_glow(
    surface: Surface, scene: Scene, sky: Sky | None, sun: FloatArray
) -> NDArray[np.float32]:
    """Luminance of a sky surface per texel (rows, cols): the sky seen from the middle of the
    floor, its glow pattern (0: no sky; else 1 + the clouds' deviation) as clouds."""
    if sky is None:
        return np.zeros(surface.glow.shape, np.float32)
    rows, cols = surface.glow.shape
    u = (np.arange(cols) + 0.5) / cols * surface.size[0]
    v = (np.arange(rows) + 0.5) / rows * surface.size[1]
    points, _ = surface.place(u[None, :], v[:, None])
    directions = points - np.array([scene.room.width / 2, scene.room.depth / 2, 0.0])
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    pattern = np.where(surface.glow > 0, 1.0 + sky.clouds * (surface.glow - 1.0), 0.0)
    return (sky_luminance(sky, directions, sun) * pattern).astype(np.float32)
