"""The outdoor style and the renderer features it needs: per-texture mip selection, floor
patches, the open sky's light and glow."""

from __future__ import annotations

import dataclasses
import hashlib

import cv2
import numpy as np
import pytest

from homebench.data.synth import textures as tx
from homebench.data.synth.atlas import Atlas, layout
from homebench.data.synth.camera import CameraSpec
from homebench.data.synth.lighting import irradiance, radiance, sky_luminance, sun_direction
from homebench.data.synth.raycast import cast
from homebench.data.synth.scene import (
    TEXELS_PER_METRE,
    Patch,
    Room,
    Scene,
    Surface,
    texture_shape,
)
from homebench.data.synth.spec import RoomSpec, WorldSpec
from homebench.data.synth.styles import style
from homebench.data.synth.world import World, build_world
from homebench.geometry import PanoramaGeometry, Pose

SEED = 1


def _outdoor(variant: str) -> WorldSpec:
    return WorldSpec(seed=SEED, style="outdoor", variant=variant)


def _rows(world: World, low_deg: float, high_deg: float) -> slice:
    """Rows of the cast panorama between two elevations."""
    el = np.degrees(
        world.panorama_geometry.row_to_elevation(np.arange(world.panorama_geometry.height))
    )
    rows = np.flatnonzero((el >= low_deg) & (el <= high_deg))
    return slice(int(rows[0]), int(rows[-1]) + 1)


# ---------------------------------------------------------------- texel density and mip levels


def _contrast(values: np.ndarray) -> float:
    low, high = np.percentile(values, [10, 90])
    return float((high - low) / (high + low))


def test_a_far_low_density_wall_keeps_its_contrast(monkeypatch):
    """A checkerboard of 1 m squares painted at 4 texels per metre on walls 30 m away: with
    each hit's own density the wall is sampled at level 0 and keeps its contrast; with the
    old fixed 100 texels per metre it was sampled at the coarsest level, 8 x blurred."""
    room = Room(60.0, 60.0, 20.0)
    density = 4.0
    shape = texture_shape(room.perimeter, room.height, density)
    wall = Surface(
        tx.checker(shape, (int(room.height), int(room.perimeter))),
        (room.perimeter, room.height),
        room.place_wall,
    )
    plain = Surface(tx.blank((2, 2), 0.3), (room.width, room.depth), room.place_plane(0.0, 1.0))
    scene = Scene(room, wall, plain, plain, [], [], [])
    spec = WorldSpec(
        room=RoomSpec(width=60.0, depth=60.0, height=20.0),
        grid={"shape": (2, 2)},
        camera=CameraSpec(exposure="fixed"),
    )
    world = World(spec, scene, 0)
    pose = Pose(30.0, 30.0, 0.3)
    band = _rows(world, -10.0, 10.0)
    sharp = world.panorama(pose)[0][band]
    assert _contrast(sharp) > 0.7

    cast = World._cast

    def fixed_density(self: World, pose: Pose):  # the footprint before per-texture densities
        hits = cast(self, pose)
        hits.density[:] = TEXELS_PER_METRE
        return hits

    monkeypatch.setattr(World, "_cast", fixed_density)
    assert _contrast(world.panorama(pose)[0][band]) < 0.3


def test_floor_patches_cover_their_rectangles():
    """Floor hits inside a patch take the patch's texture and density, the innermost patch
    wins, and hits outside keep the floor's."""
    room = Room(20.0, 20.0, 5.0)
    floor = Surface(tx.blank((40, 40), 0.2), (20.0, 20.0), room.place_plane(0.0, 1.0))
    patches = [
        Patch((6.0, 14.0), (6.0, 14.0), tx.blank(texture_shape(8.0, 8.0, 10.0), 0.5)),
        Patch((8.0, 12.0), (9.0, 11.0), tx.blank(texture_shape(4.0, 2.0, 50.0), 0.9)),
    ]
    scene = Scene(room, floor, floor, floor, [], [], [], patches)
    surfaces = scene.surfaces()
    regions, shape = layout([s.albedo.shape for s in surfaces], [s.scale for s in surfaces], 5)
    atlas = Atlas([s.albedo for s in surfaces], regions, shape)
    geometry = PanoramaGeometry(360, 60, np.radians(-5), np.radians(-80))
    origin = (10.5, 10.2, 1.5)
    hits = cast(scene, regions, geometry, origin, 0.0)
    value = atlas.sample(hits.x, hits.y, np.zeros(hits.x.shape, np.float32))
    az, el = geometry.bearing_grid()
    x = origin[0] + hits.rho * np.cos(az)
    y = origin[1] + hits.rho * np.sin(az)

    def within(x0: float, x1: float, y0: float, y1: float, margin: float) -> np.ndarray:
        return (x > x0 + margin) & (x < x1 - margin) & (y > y0 + margin) & (y < y1 - margin)

    inner = within(8.0, 12.0, 9.0, 11.0, 0.05)
    outer = within(6.0, 14.0, 6.0, 14.0, 0.05) & ~within(8.0, 12.0, 9.0, 11.0, -0.05)
    outside = ~within(6.0, 14.0, 6.0, 14.0, -0.05)
    for where, grey, density in ((inner, 0.9, 50.0), (outer, 0.5, 10.0), (outside, 0.2, 2.0)):
        assert where.sum() > 50
        assert np.allclose(value[where], grey, atol=1e-4)
        assert np.allclose(hits.density[where], density, rtol=0.02)


def test_the_ground_near_the_cameras_is_sharp():
    """The detailed patch round the grid gives the lower rows (looking down) fine texture:
    over twice the high-frequency energy of the same place on the coarse ground alone."""
    spec = _outdoor("winlit")
    world = build_world(spec)
    coarse = World(spec, dataclasses.replace(world.scene, patches=[]), len(world.scene.objects))
    energy = []
    for w in (world, coarse):
        image = w.render(spec.pose(4, 8), None)["unfolded"].astype(np.float32)
        low = image[-25:]  # about -50 to -25 deg
        energy.append(float(np.abs(low - cv2.GaussianBlur(low, (0, 0), 1.5)).mean()))
    assert energy[0] > 2.0 * energy[1]
    assert energy[0] > 2.0  # grey levels: visible texture, not only the mip of a coarse floor


# ---------------------------------------------------------------- light under the open sky


@pytest.mark.parametrize("variant", ["original", "twilight", "winlit"])
def test_the_sky_glows_and_is_bright(variant):
    """The sky is a light source (its surfaces have no albedo, yet radiance) and it is not
    saturated away from the sun's disc; without the sun it is brighter than the ground it
    lights (under a hazy sun, sunlit paving may match it)."""
    spec = _outdoor(variant)
    world = build_world(spec)
    scene, lighting = world.scene, world.lighting
    sun = sun_direction(scene, lighting, spec.seed)
    assert scene.ceiling.albedo.max() == 0
    assert radiance(scene.ceiling, scene, lighting, sun).min() > 0
    image = world.render(spec.pose(5, 9), None)["unfolded"].astype(np.float32)
    labels = world.render_labels(spec.pose(5, 9))["unfolded"]
    top, bottom = slice(5, 25), slice(-30, None)  # about 40 to 20 deg up, -20 to -50 down
    sky = image[top][labels[top] == 0]
    assert sky.mean() > 90 and np.percentile(sky, 99) < 250
    if lighting.sky.sun == 0:
        assert sky.mean() > image[bottom].mean() + 20


def _facing(spec: WorldSpec) -> tuple[float, float]:
    """Irradiance of a vertical surface facing the sun and one facing away, 2 m up at the
    grid's middle, unshadowed."""
    world = build_world(spec)
    scene, lighting = world.scene, world.lighting
    sun = sun_direction(scene, lighting, spec.seed)
    toward = np.array([sun[0], sun[1], 0.0]) / np.hypot(sun[0], sun[1])
    x, y = spec.pose(5, 8).xy
    points = np.array([[x, y, 2.0], [x, y, 2.0]])
    e = irradiance(scene, lighting, sun, points, np.stack([toward, -toward]), shadows=False)
    return float(e[0]), float(e[1])


def test_day_sun_lights_the_faces_towards_it():
    toward, away = _facing(_outdoor("day"))
    assert toward > 2.5 * away
    toward_original, away_original = _facing(_outdoor("original"))
    assert 1.0 < toward_original / away_original < toward / away  # a milder sun


def test_the_cloudy_variant_has_no_sun():
    spec = _outdoor("winlit")
    lighting = style("outdoor").lightings["winlit"]
    assert lighting.sky is not None and lighting.sky.sun == 0
    toward, away = _facing(spec)
    assert toward == pytest.approx(away)
    sun = sun_direction(build_world(spec).scene, lighting, SEED)
    up = np.radians(np.linspace(0, 90, 91))
    directions = np.stack([np.cos(up), 0 * up, np.sin(up)], axis=-1)
    luminance = sky_luminance(lighting.sky, directions, sun)
    assert np.all(np.diff(luminance) >= 0)  # overcast: brightest at the zenith, no sun's disc


def test_objects_cast_sun_shadows_on_the_ground():
    """In ``day`` the ground just behind a tree trunk (away from the sun) is in its shadow:
    it gets the sky's light but not the sun's."""
    spec = _outdoor("day")
    world = build_world(spec)
    scene, lighting = world.scene, world.lighting
    sun = sun_direction(scene, lighting, spec.seed)
    trunk = next(o for o in scene.objects if o.name.endswith("/trunk"))
    away = -np.array([sun[0], sun[1]]) / np.hypot(sun[0], sun[1])
    behind = np.array(trunk.centre) + (trunk.radius + 0.3) * away
    point, up = np.array([[*behind, 0.0]]), np.array([[0.0, 0.0, 1.0]])
    shaded = irradiance(scene, lighting, sun, point, up)[0]
    unshaded = irradiance(scene, lighting, sun, point, up, shadows=False)[0]
    assert shaded < 0.5 * unshaded
    assert shaded > 0.1 * unshaded  # the sky still lights it


# ---------------------------------------------------------------- determinism and cost


def _digest(images: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for kind in sorted(images):
        h.update(kind.encode() + images[kind].tobytes())
    return h.hexdigest()


def test_a_spec_gives_bit_identical_images_and_a_small_atlas():
    spec = _outdoor("original")
    world = build_world(spec)
    extent = spec.room_extent
    room = Room(extent.width, extent.depth, extent.height)
    rebuilt = World(
        spec, style("outdoor").build(SEED, room, spec.to_grid()), len(world.scene.objects)
    )
    pose = spec.pose(3, 12)
    assert _digest(world.render(pose, 7)) == _digest(rebuilt.render(pose, 7))
    assert sum(level.nbytes for level in world.atlas.levels) < 80e6
