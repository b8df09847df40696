"""A vectorised, separable ray caster for equiangular panoramas of a :class:`Scene`.

Rays are the pixel centres of a :class:`PanoramaGeometry`. Distances are measured
horizontally (rho): a ray's horizontal direction depends only on its column and its slope
(tan elevation) only on its row, so every footprint crossing is a 1-D computation per column,
every height crossing a 1-D computation per row, and a prism's hits are their intersection on
the block of rows x columns it can cover (a z-buffer on rho). Floor hits inside a floor patch
take the patch's texture; every hit records the density of the texture it took (for the mip
level).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from homebench.data.synth.atlas import Region
from homebench.data.synth.scene import Prism, Scene
from homebench.geometry import PanoramaGeometry

Float32 = NDArray[np.float32]
FloatArray = NDArray[np.float64]
_TINY = 1e-12


@dataclass
class Hits:
    """Per-pixel results, each (height, width): horizontal distance ``rho`` (m), object
    ``label`` (0 = room), level-0 atlas coordinates (``x``, ``y``), the |cosine| of the
    incidence angle and the ``density`` (texels per metre) of the texture hit."""

    rho: Float32
    label: NDArray[np.int32]
    x: Float32
    y: Float32
    cos_incidence: Float32
    density: Float32


@dataclass(frozen=True)
class _Rays:
    ox: float
    oy: float
    oz: float
    c: FloatArray  # (W,) cos of world direction
    s: FloatArray  # (W,) sin of world direction
    tan: FloatArray  # (H,) tan elevation, never exactly 0
    cos_el: FloatArray  # (H,)
    sin_el: FloatArray  # (H,)

    def slab(self, z0: float, z1: float) -> tuple[FloatArray, FloatArray]:
        """Per row, the rho interval where the ray's height lies in [z0, z1]; each (H,)."""
        a, b = (z0 - self.oz) / self.tan, (z1 - self.oz) / self.tan
        return np.minimum(a, b), np.maximum(a, b)


def _runs(mask: NDArray[np.bool_]) -> list[slice]:
    """Slices of the runs of True in a 1-D mask."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
    return [slice(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def cast(
    scene: Scene,
    regions: list[Region],
    geometry: PanoramaGeometry,
    origin: tuple[float, float, float],
    heading: float,
) -> Hits:
    """Cast every pixel ray of ``geometry`` from ``origin`` (x, y, z) for a robot ``heading``.

    ``regions`` are the atlas regions of ``scene.surfaces()``, in that order.
    """
    direction = heading + geometry.column_to_azimuth(np.arange(geometry.width))
    elevation = geometry.row_to_elevation(np.arange(geometry.height))
    tan = np.tan(elevation)
    tan = np.where(np.abs(tan) < _TINY, _TINY, tan)
    rays = _Rays(
        *origin, np.cos(direction), np.sin(direction), tan, np.cos(elevation), np.sin(elevation)
    )
    hits = _cast_room(scene, regions, rays)
    n_room = len(scene.room_surfaces())
    for k, obj in enumerate(scene.objects):
        first = n_room + 3 * k
        _cast_prism(hits, obj, k + 1, regions[first : first + 3], rays)
    return hits


def _cast_room(scene: Scene, regions: list[Region], rays: _Rays) -> Hits:
    room = scene.room
    _, rho_wall, u_wall, cos_wall = room.crossing(rays.ox, rays.oy, rays.c, rays.s)
    up = rays.tan > 0
    rho_plane = np.where(up, room.height - rays.oz, -rays.oz) / rays.tan
    wall = rho_wall[None, :] <= rho_plane[:, None]
    rho = np.minimum(rho_wall[None, :], rho_plane[:, None])
    z = rays.oz + rho * rays.tan[:, None]
    wx, wy = regions[0].coords(u_wall[None, :], room.height - z)
    px, py = rays.ox + rho * rays.c, rays.oy + rho * rays.s
    pu, pv = room.plane_uv(px, py)
    fx, fy = regions[1].coords(pu, pv)
    cx, cy = regions[2].coords(pu, pv)
    up2 = up[:, None]
    x = np.where(wall, wx, np.where(up2, cx, fx))
    y = np.where(wall, wy, np.where(up2, cy, fy))
    density = np.where(
        wall, regions[0].density, np.where(up2, regions[2].density, regions[1].density)
    ).astype(np.float32)
    patch_regions = regions[3 : 3 + len(scene.patches)]
    for patch, region in zip(scene.patches, patch_regions, strict=True):
        on = ~wall & ~up2 & patch.contains(px, py)
        x[on], y[on] = region.coords(*patch.uv(px[on], py[on]))
        density[on] = region.density
    cos_inc = np.where(wall, rays.cos_el[:, None] * cos_wall[None, :], np.abs(rays.sin_el)[:, None])
    return Hits(
        rho.astype(np.float32),
        np.zeros(rho.shape, np.int32),
        x,
        y,
        cos_inc.astype(np.float32),
        density,
    )


def _cast_prism(hits: Hits, obj: Prism, label: int, regions: list[Region], rays: _Rays) -> None:
    rho_in, rho_out, u, cos_h = obj.crossing(rays.ox, rays.oy, rays.c, rays.s)
    columns = rho_out > np.maximum(rho_in, 0.0)
    if not columns.any():
        return
    lo, hi = rays.slab(obj.z0, obj.z1)
    near, far = max(float(rho_in[columns].min()), 0.0), float(rho_out[columns].max())
    rows = np.flatnonzero((hi > near) & (lo < far))
    if rows.size == 0:
        return
    rs = slice(int(rows[0]), int(rows[-1]) + 1)
    side_region, top_region, bottom_region = regions
    top = (rays.tan[rs] < 0)[:, None]
    cap_density = np.where(top, top_region.density, bottom_region.density)
    for cs in _runs(columns):
        entry = np.maximum(rho_in[cs][None, :], lo[rs][:, None])
        leave = np.minimum(rho_out[cs][None, :], hi[rs][:, None])
        hit = (entry <= leave) & (entry > 0) & (entry < hits.rho[rs, cs])
        if not hit.any():
            continue
        side = rho_in[cs][None, :] >= lo[rs][:, None]
        z = rays.oz + entry * rays.tan[rs][:, None]
        sx, sy = side_region.coords(u[cs][None, :], obj.z1 - z)
        cu, cv = obj.cap_uv(rays.ox + entry * rays.c[cs], rays.oy + entry * rays.s[cs])
        tx, ty = top_region.coords(cu, cv)
        bx, by = bottom_region.coords(cu, cv)
        cos_inc = np.where(
            side, rays.cos_el[rs][:, None] * cos_h[cs][None, :], np.abs(rays.sin_el[rs])[:, None]
        )
        density = np.where(side, side_region.density, cap_density)
        block = (rs, cs)
        np.copyto(hits.rho[block], entry, where=hit, casting="unsafe")
        np.copyto(hits.label[block], label, where=hit)
        np.copyto(hits.x[block], np.where(side, sx, np.where(top, tx, bx)), where=hit)
        np.copyto(hits.y[block], np.where(side, sy, np.where(top, ty, by)), where=hit)
        np.copyto(hits.cos_incidence[block], cos_inc, where=hit, casting="unsafe")
        np.copyto(hits.density[block], density, where=hit, casting="unsafe")
