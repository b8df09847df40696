"""Scene primitives, the ray caster, the atlas and the seeded layout against ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.data.synth import textures as tx
from homebench.data.synth.atlas import LEVELS, Atlas, layout
from homebench.data.synth.layout import GRID_MARGIN
from homebench.data.synth.raycast import cast
from homebench.data.synth.scene import Box, Cylinder, Room, Scene
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.styles.posters import build as base_scene
from homebench.data.synth.world import build_world
from homebench.geometry import Grid, PanoramaGeometry

ROOM = Room(6.0, 8.4, 2.8)
GRID = Grid((10, 17), 0.3, (1.65, 1.8))
PRISMS = [
    Box(
        "box",
        0.2,
        1.1,
        tx.blank((4, 4), 0.5),
        tx.blank((4, 4), 0.5),
        centre=(4.0, 2.0),
        size=(0.8, 0.5),
        angle=0.6,
    ),
    Cylinder(
        "cyl", 0.0, 0.7, tx.blank((4, 4), 0.5), tx.blank((4, 4), 0.5), centre=(1.5, 6.0), radius=0.3
    ),
]


def _directions(n: int = 720) -> tuple[np.ndarray, np.ndarray]:
    a = (np.arange(n) + 0.5) * 2 * np.pi / n
    return np.cos(a), np.sin(a)


@pytest.mark.parametrize("prism", PRISMS, ids=lambda p: p.name)
def test_footprint_crossing_matches_marching(prism):
    c, s = _directions()
    ox, oy = 3.0, 4.0
    rho_in, rho_out, u, _ = prism.crossing(ox, oy, c, s)
    t = np.linspace(0, 8, 4001)
    for k in range(0, len(c), 15):
        inside = [prism.distance_xy(ox + ti * c[k], oy + ti * s[k]) <= 0 for ti in t]
        if not any(inside):
            assert not rho_out[k] > max(rho_in[k], 0)
            continue
        first, last = t[np.argmax(inside)], t[len(t) - 1 - np.argmax(inside[::-1])]
        assert rho_in[k] == pytest.approx(first, abs=3e-3)
        assert rho_out[k] == pytest.approx(last, abs=3e-3)
        # the side texture coordinate at the entry places a point back at the entry
        points, _ = prism.surfaces()[0].place(np.array(u[k]), np.array(0.0))
        assert points[:2] == pytest.approx([ox + rho_in[k] * c[k], oy + rho_in[k] * s[k]], abs=1e-9)


@pytest.mark.parametrize("prism", PRISMS, ids=lambda p: p.name)
def test_cap_coordinates_invert(prism):
    rng = np.random.default_rng(1)
    ring = prism.outline()
    xy = rng.uniform(ring.min(axis=0), ring.max(axis=0), size=(200, 2))
    xy = xy[[prism.distance_xy(x, y) < 0 for x, y in xy]]
    u, v = prism.cap_uv(xy[:, 0], xy[:, 1])
    assert np.all((u >= 0) & (u <= prism.cap_size[0]) & (v >= 0) & (v <= prism.cap_size[1]))
    points, normals = prism.surfaces()[1].place(u, v)
    assert np.allclose(points[:, :2], xy) and np.allclose(points[:, 2], prism.z1)
    assert np.allclose(normals, [0, 0, 1])


def test_room_crossing_lands_on_the_walls():
    c, s = _directions()
    _, rho, u, cos_h = ROOM.crossing(2.0, 5.0, c, s)
    x, y = 2.0 + rho * c, 5.0 + rho * s
    on_wall = np.isclose(x, 0) | np.isclose(x, 6.0) | np.isclose(y, 0) | np.isclose(y, 8.4)
    assert np.all(on_wall)
    wx, wy, nx, ny = ROOM.wall_xy(u)
    assert np.allclose(wx, x) and np.allclose(wy, y)
    assert np.allclose(cos_h, np.abs(nx * c + ny * s))


def test_cast_hits_lie_on_the_labelled_surfaces():
    scene = Scene(ROOM, *(None,) * 3, PRISMS, [], [])  # type: ignore[arg-type]
    shapes = [(4, 4)] * (3 + 3 * len(PRISMS))
    regions, _ = layout(shapes, [(1.0, 1.0)] * len(shapes), len(shapes))
    geometry = PanoramaGeometry(240, 100, np.radians(60), np.radians(-60))
    origin, heading = (3.0, 4.0, 0.9), 0.7
    hits = cast(scene, regions, geometry, origin, heading)
    az, el = geometry.bearing_grid()
    world_dir = heading + az
    dist = hits.rho.astype(np.float64)
    x = origin[0] + dist * np.cos(world_dir)
    y = origin[1] + dist * np.sin(world_dir)
    z = origin[2] + dist * np.tan(el)
    for k, prism in enumerate(PRISMS, start=1):
        mine = hits.label == k
        assert mine.sum() > 20
        gaps = [prism.clearance(a, b, c) for a, b, c in zip(x[mine], y[mine], z[mine], strict=True)]
        assert max(gaps) < 1e-4
    room = hits.label == 0
    edge = np.minimum.reduce(
        [
            x[room],
            ROOM.width - x[room],
            y[room],
            ROOM.depth - y[room],
            z[room],
            ROOM.height - z[room],
        ]
    )
    assert np.abs(edge).max() < 1e-4


def test_atlas_tiles_do_not_bleed_and_appending_keeps_the_base():
    textures = [np.full((40, 60), 10.0, np.float32), np.full((30, 30), 200.0, np.float32)]
    shapes = [t.shape for t in textures]
    regions, shape = layout(shapes, [(10.0, 10.0)] * 2, 2)
    more, _ = layout([*shapes, (50, 50)], [(10.0, 10.0)] * 3, 2)
    assert more[:2] == regions
    atlas = Atlas(textures, regions, shape)
    for region, value in zip(regions, (10.0, 200.0), strict=True):
        # surface corners and far outside the surface are clamped to the tile
        u = np.array([[-1.0, 0.0, region.size[0] / 10.0, 99.0]], np.float64)
        x, y = region.coords(u, np.zeros_like(u))
        for level in range(LEVELS):
            got = atlas.sample(x, y, np.full(x.shape, float(level), np.float32))
            assert np.allclose(got, value, atol=1e-3)


def test_layout_keeps_objects_off_the_grid_and_in_the_room():
    scene = base_scene(3, ROOM, GRID)
    assert len(scene.objects) >= 8 and scene.windows and scene.bars
    (x0, y0), (x1, y1) = GRID.position(0, 0), GRID.position(9, 16)
    for obj in scene.objects:
        ring = obj.outline()
        assert ring.min() > 0 and ring[:, 0].max() < ROOM.width and ring[:, 1].max() < ROOM.depth
        dx = np.maximum(np.maximum(x0 - ring[:, 0], ring[:, 0] - x1), 0)
        dy = np.maximum(np.maximum(y0 - ring[:, 1], ring[:, 1] - y1), 0)
        assert np.hypot(dx, dy).min() > GRID_MARGIN - 1e-9 or obj.z0 > 0  # stacked items too
    for texture in (scene.wall.albedo, scene.floor.albedo, scene.ceiling.albedo):
        assert texture.dtype == np.float32 and texture.min() >= 0 and texture.max() <= 1
        assert texture.std() > 0.05


def test_layout_is_seeded():
    a, b, c = (base_scene(s, ROOM, GRID) for s in (3, 3, 4))
    assert [o.corners() for o in a.objects] == [o.corners() for o in b.objects]
    assert np.array_equal(a.wall.albedo, b.wall.albedo)
    assert not np.array_equal(a.wall.albedo, c.wall.albedo)
    assert [o.corners() for o in a.objects] != [o.corners() for o in c.objects]


def test_world_uses_the_spec_room():
    spec = WorldSpec(
        seed=1, room={"width": 4.0, "depth": 6.0, "height": 2.5}, grid={"shape": (4, 6)}
    )
    truth = build_world(spec).ground_truth()
    assert truth["room"] == {"width": 4.0, "depth": 6.0, "height": 2.5}
    corners = np.array([p for o in truth["objects"] for p in o["corners"]])
    assert corners[:, 0].max() < 4.0 and corners[:, 1].max() < 6.0 and corners[:, 2].max() < 2.5
