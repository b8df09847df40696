"""Light in the room, baked into the textures: radiance = albedo x irradiance + glow.

Sources: a uniform ambient term (inter-reflections), the ceiling's fluorescent bars, the
window(s) as diffuse area lights and, in ``day``, the sun through the window(s) (sun patches).
No object casts shadows, so an added object changes only the pixels it covers. Irradiance is
computed on a coarse grid of each texture (every :data:`LIGHTMAP_STEP` texels) and upsampled:
light varies slowly. Units: grey levels for a white (albedo 1) surface; the camera clips at
255 later.
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


@dataclass(frozen=True)
class Lighting:
    """One lighting condition (intensities in grey levels for a white surface)."""

    ambient: float
    ceiling: float  # irradiance scale of each light bar
    window: float  # irradiance scale of each window's diffuse light
    sun: float  # irradiance in sun patches (0: no sun)
    lights_glow: float  # luminance of the light bars' diffusers when on
    window_glow: float  # luminance of the view outside when the curtains are open
    curtains_open: bool
    noise_scale: float = 1.0  # multiplies the spec's sensor noise


LIGHTINGS: dict[Variant, Lighting] = {
    "original": Lighting(110.0, 230.0, 0.0, 0.0, 600.0, 0.0, False),
    "arboreal": Lighting(110.0, 230.0, 0.0, 0.0, 600.0, 0.0, False),
    "chairs": Lighting(110.0, 230.0, 0.0, 0.0, 600.0, 0.0, False),
    "day": Lighting(120.0, 230.0, 2200.0, 1100.0, 600.0, 1500.0, True),
    "twilight": Lighting(60.0, 0.0, 220.0, 0.0, 0.0, 200.0, True, noise_scale=2.5),
    "winlit": Lighting(60.0, 0.0, 800.0, 0.0, 0.0, 700.0, True),
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


def sun_direction(scene: Scene, seed: int) -> FloatArray:
    """Unit vector towards the sun (3,): out through the first window, 25-40 deg up.

    Drawn from its own stream ``default_rng([seed, 2])``; (0, 0, 1) without windows.
    """
    if not scene.windows:
        return np.array([0.0, 0.0, 1.0])
    rng = np.random.default_rng([seed, 2])
    w = scene.windows[0]
    _, inward = w.emitters(scene.room, 1)
    out_angle = np.arctan2(-inward[1], -inward[0]) + rng.uniform(-0.6, 0.6)
    elevation = rng.uniform(np.radians(25), np.radians(40))
    return np.array(
        [
            np.cos(elevation) * np.cos(out_angle),
            np.cos(elevation) * np.sin(out_angle),
            np.sin(elevation),
        ]
    )


def irradiance(
    scene: Scene, lighting: Lighting, sun: FloatArray, points: FloatArray, normals: FloatArray
) -> FloatArray:
    """Irradiance at world points (..., 3) with unit normals (..., 3); shape (...)."""
    e = np.full(points.shape[:-1], lighting.ambient)
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
    e = irradiance(scene, lighting, sun, points, normals).astype(np.float32)
    e = cv2.resize(e, (cols, rows), interpolation=cv2.INTER_LINEAR)
    albedo = surface.albedo
    if lighting.curtains_open and surface.albedo_open is not None:
        albedo = surface.albedo_open
    out = albedo * e
    if surface.glow is not None:
        glow = lighting.lights_glow if surface.glow_kind == "lights" else lighting.window_glow
        if not lighting.curtains_open and surface.glow_kind == "window":
            glow = 0.0
        out = out + glow * surface.glow
    return out.astype(np.float32)
