"""A generated world: build it from a :class:`WorldSpec`, render any pose in both image kinds.

One cast per pose: rays for a supersampled equiangular panorama (``SUPERSAMPLE`` x the
unfolded resolution, covering the elevations of both cameras), textures sampled from the lit
atlas with trilinear mip-mapping. The unfolded image is that panorama area-averaged (its
``zero_column`` is set so that each block of columns centres on the unfolded column's azimuth);
the raw image is :func:`~homebench.imaging.projection.fold` of it. Both pass through one
capture of the world's camera (:mod:`homebench.data.synth.camera`): optics on the cast
panorama, one exposure per pose, then a sensor read-out per image kind whose noise is seeded
by (noise seed, image kind) and never by the variant. A camera spec with ``tilt_deg`` > 0
tilts each capture's view axis (:mod:`homebench.data.synth.tilt`) by a tilt drawn from the
same seed (its own stream): a grid position's tilt is therefore the same in every variant (the
floor is), and zero tilt renders exactly as before. With a fixed exposure, pixels that an
added object does not touch (nor, under an open sky with sun, shade) are therefore
bit-identical between variants; with auto-exposure
(the default) an added object changes the metered light, hence every pixel slightly, as in a
real camera. A spec's ``render: landmarks`` gives its ground-truth landmark images instead
(:meth:`World.render_landmarks`: objects black on a white room, no light, no camera).
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from functools import lru_cache
from typing import Any, Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.data.synth.atlas import LEVELS, Atlas, layout
from homebench.data.synth.camera import Camera, Exposure
from homebench.data.synth.layout import variant_objects
from homebench.data.synth.lighting import radiance, sun_direction
from homebench.data.synth.raycast import Hits, cast
from homebench.data.synth.scene import TEXELS_PER_METRE, Room, Scene
from homebench.data.synth.spec import Style, WorldSpec
from homebench.data.synth.styles import style
from homebench.data.synth.tilt import Tilt, level_geometry, tilted
from homebench.errors import HomebenchError
from homebench.geometry import CatadioptricGeometry, Grid, PanoramaGeometry, Pose, grid_key
from homebench.imaging.projection import fold, fold_labels, frontmost, tangential_prefilter

#: Rows and columns of the cast panorama per unfolded pixel.
SUPERSAMPLE = 4
#: Supersampling of the fold to the raw image.
RAW_SUPERSAMPLE = 2
#: Closest a camera may come to a wall or an object, metres.
MIN_CLEARANCE = 0.02
#: Grey levels of the ground-truth landmark images (``render: landmarks``): objects, room.
LANDMARK_GREYS = (0, 255)
_KIND_STREAM = {"raw": 0, "unfolded": 1}
_TILT_STREAM = 2
_CACHE_SIZE = 6
_worlds: OrderedDict[str, World] = OrderedDict()


PoseFault = Literal["collision", "outside"]


class PoseError(HomebenchError):
    """A pose that cannot be rendered, and why (``fault``): ``collision``, inside an object or
    beyond the room's walls; ``outside``, beyond what a database shows (a grid's extent, a
    recording's reach), where nothing stops a robot."""

    def __init__(self, message: str, fault: PoseFault = "collision") -> None:
        super().__init__(message)
        self.fault: PoseFault = fault

    def __reduce__(self) -> tuple[type[PoseError], tuple[str, PoseFault]]:
        return type(self), (str(self), self.fault)


def supersampled_geometry(
    unfolded: PanoramaGeometry, raw: CatadioptricGeometry, k: int
) -> tuple[PanoramaGeometry, slice]:
    """The cast panorama for an unfolded geometry and a raw one, and the rows to crop.

    ``k x k`` pixels of it average to one unfolded pixel; it extends the unfolded elevation
    range by whole unfolded rows (plus one) to cover the raw annulus.
    """
    step = unfolded.row_step
    top = max(unfolded.elevation_top, max(raw.elevations))
    bottom = min(unfolded.elevation_bottom, min(raw.elevations))
    above = math.ceil((top - unfolded.elevation_top) / step - 1e-9) + 1
    below = math.ceil((unfolded.elevation_bottom - bottom) / step - 1e-9) + 1
    geometry = PanoramaGeometry(
        width=k * unfolded.width,
        height=k * (unfolded.height + above + below),
        elevation_top=unfolded.elevation_top + above * step,
        elevation_bottom=unfolded.elevation_bottom - below * step,
        direction=unfolded.direction,
        zero_column=k * unfolded.zero_column + (k - 1) / 2.0,
    )
    return geometry, slice(k * above, k * (above + unfolded.height))


def position_noise_seed(seed: int, i: int, j: int) -> int:
    """The sensor-noise seed of grid position (i, j) of a world seed (independent of variant)."""
    digest = hashlib.sha256(f"homebench-noise:{seed}:{i}:{j}".encode()).digest()
    return int.from_bytes(digest[:8], "little")


class World:
    """A scene under one variant's lighting, ready to render (see :func:`build_world`).

    The first ``n_base_objects`` of ``scene.objects`` are the base layout: their atlas tiles
    come first, so objects appended after them (a variant's, or a test's marker) change nothing
    else in the images.
    """

    def __init__(self, spec: WorldSpec, scene: Scene, n_base_objects: int):
        self.spec, self.scene = spec, scene
        self.lighting = style(spec.style).lightings[spec.variant]
        self.raw_geometry = spec.raw.geometry()
        self.unfolded_geometry = spec.unfolded.geometry()
        self.panorama_geometry, self._rows = supersampled_geometry(
            self.unfolded_geometry, self.raw_geometry, SUPERSAMPLE
        )
        self._upright_geometry = (
            level_geometry(self.panorama_geometry, spec.camera.tilt_deg)
            if spec.camera.tilt_deg > 0
            else self.panorama_geometry
        )
        surfaces = scene.surfaces()
        self.regions, shape = layout(
            [s.albedo.shape for s in surfaces],
            [s.scale for s in surfaces],
            n_base=len(scene.room_surfaces()) + 3 * n_base_objects,
        )
        sun = sun_direction(scene, self.lighting, spec.seed)
        gain = np.float32(spec.light_gain)
        lit = [radiance(s, scene, self.lighting, sun) * gain for s in surfaces]
        self.atlas = Atlas(lit, self.regions, shape)
        self.camera = Camera(spec.camera, self.panorama_geometry, self.raw_geometry)
        self._annulus = self.raw_geometry.annulus_mask()

    # ------------------------------------------------------------------ rendering

    def check_pose(self, pose: Pose) -> None:
        """Raise :class:`PoseError` unless the camera at ``pose`` is in free space."""
        room, z = self.scene.room, self.spec.camera_height
        m = MIN_CLEARANCE
        if not (m < pose.x < room.width - m and m < pose.y < room.depth - m):
            raise PoseError(
                f"pose ({pose.x:.3f}, {pose.y:.3f}) m is outside the room "
                f"[0, {room.width}] x [0, {room.depth}] m (world seed {self.spec.seed})"
            )
        for obj in self.scene.objects:
            if obj.clearance(pose.x, pose.y, z) < m:
                raise PoseError(
                    f"pose ({pose.x:.3f}, {pose.y:.3f}) m puts the camera inside object "
                    f"{obj.name!r} (world seed {self.spec.seed}, variant {self.spec.variant})"
                )

    def panorama(
        self, pose: Pose, geometry: PanoramaGeometry | None = None
    ) -> tuple[NDArray[np.float32], Hits]:
        """Noise-free radiance (grey levels, unclipped) of the upright cast panorama and its
        ray hits.

        Shapes (height, width) of ``geometry`` (default :attr:`panorama_geometry`). Each
        pixel's mip level is log2 of the texels its footprint covers: distance x pixel angle x
        the density of the texture hit, over the cosine of incidence (floored at 0.15).
        """
        g = geometry or self.panorama_geometry
        hits = self._cast(pose) if geometry is None else self._cast(pose, geometry)
        pixel_angle = max(g.row_step, g.column_step)
        # texels per pixel: distance x pixel angle x the hit texture's own density, written so
        # that a texture of exactly TEXELS_PER_METRE gives the same floats as a fixed density
        footprint = hits.rho / _cos_rows(g) * np.float32(pixel_angle * TEXELS_PER_METRE)
        footprint *= hits.density / np.float32(TEXELS_PER_METRE)
        footprint /= np.maximum(hits.cos_incidence, np.float32(0.15))
        level = np.clip(np.log2(np.maximum(footprint, 1.0)), 0, LEVELS - 1)
        return self.atlas.sample(hits.x, hits.y, level), hits

    def _cast(self, pose: Pose, geometry: PanoramaGeometry | None = None) -> Hits:
        self.check_pose(pose)
        origin = (pose.x, pose.y, self.spec.camera_height)
        g = geometry or self.panorama_geometry
        return cast(self.scene, self.regions, g, origin, pose.heading)

    def downsample(self, panorama: NDArray) -> NDArray:
        """The unfolded image of a cast panorama (height, width of :attr:`panorama_geometry`):
        crop to the unfolded rows and area-average ``SUPERSAMPLE x SUPERSAMPLE`` blocks."""
        crop = panorama[self._rows]
        g = self.unfolded_geometry
        return cv2.resize(crop, (g.width, g.height), interpolation=cv2.INTER_AREA)

    def tilt(self, seed: int | None) -> Tilt | None:
        """The mount's tilt of the capture seeded by ``seed`` (None: upright, as is every
        capture of a camera without ``tilt_deg``)."""
        if seed is None or self.spec.camera.tilt_deg <= 0:
            return None
        return self._draw_tilt(seed)

    def _draw_tilt(self, seed: int) -> Tilt:
        return Tilt.draw(self.spec.camera.tilt_deg, np.random.default_rng([seed, _TILT_STREAM]))

    def capture(self, pose: Pose, tilt: Tilt | None = None) -> tuple[NDArray[np.float32], Exposure]:
        """The radiance reaching the sensor at ``pose`` with the camera axis tilted by
        ``tilt`` (None: upright), after the optics (shape of :attr:`panorama_geometry`), and
        the exposure the camera chooses for it."""
        if tilt is None:
            radiance = self.panorama(pose)[0]
        else:
            upright = self.panorama(pose, self._upright_geometry)[0]
            radiance = tilted(upright, self._upright_geometry, self.panorama_geometry, tilt)
        seen = self.camera.optics(radiance)
        return seen, self.camera.meter(seen)

    def _fold(self, panorama: NDArray[np.float32]) -> NDArray[np.float32]:
        """The raw image of a cast panorama: anti-aliased along the mirror's circles, folded."""
        pano, raw = self.panorama_geometry, self.raw_geometry
        filtered = tangential_prefilter(panorama, pano, raw, RAW_SUPERSAMPLE)
        return fold(filtered, pano, raw, RAW_SUPERSAMPLE)

    def render(self, pose: Pose, noise_seed: int | None) -> dict[str, NDArray[np.uint8]]:
        """Grey images of ``pose``: "raw" (raw.height, raw.width) and "unfolded"
        (unfolded.height, unfolded.width). ``noise_seed`` seeds the capture's randomness:
        the sensor noise and the mount's tilt (:meth:`tilt`); None renders without either.
        The spec's ``render: landmarks`` gives :meth:`render_landmarks` instead."""
        if self.spec.render == "landmarks":
            return self.render_landmarks(pose)
        seen, exposure = self.capture(pose, self.tilt(noise_seed))
        camera = self.camera
        return {
            "raw": camera.read_out(
                self._fold(seen),
                exposure,
                noise_seed,
                _KIND_STREAM["raw"],
                self._annulus,
            ),
            "unfolded": camera.read_out(
                self.downsample(seen), exposure, noise_seed, _KIND_STREAM["unfolded"]
            ),
        }

    def render_landmarks(self, pose: Pose) -> dict[str, NDArray[np.uint8]]:
        """The ground-truth landmark images of ``pose``, same keys and shapes as :meth:`render`:
        black (:data:`LANDMARK_GREYS`) every pixel that sees an object (:meth:`render_labels`:
        label > 0, the frontmost of its cast samples, so that a thin or far object keeps its
        pixels), white the room (walls, floor, ceiling); a raw image is black outside its
        annulus. No light and no camera (exposure, blur, noise, response): the ideal sensor of
        a control, and two grey levels only, so that any threshold between them segments it
        alike."""
        dark, bright = LANDMARK_GREYS
        images = {
            kind: np.where(labels > 0, dark, bright).astype(np.uint8)
            for kind, labels in self.render_labels(pose).items()
        }
        images["raw"][~self._annulus] = 0
        return images

    def render_labels(self, pose: Pose) -> dict[str, NDArray[np.int32]]:
        """Object id seen at each pixel (0 = room surfaces); same keys and shapes as
        :meth:`render`. No interpolation: each pixel takes the id of the frontmost of the cast
        samples its grey value is made from, so thin objects (chair legs) keep their pixels."""
        hits = self._cast(pose)
        rows = self._rows
        return {
            "raw": fold_labels(
                hits.label, hits.rho, self.panorama_geometry, self.raw_geometry, RAW_SUPERSAMPLE
            ),
            "unfolded": frontmost(hits.label[rows], hits.rho[rows], SUPERSAMPLE),
        }

    # ------------------------------------------------------------------ description

    def ground_truth(self) -> dict[str, Any]:
        """Room, camera height and every object with its 3-D corner points (JSON-ready); with
        a tilted camera also each grid position's tilt (``camera_tilts``, by "i_j": angle and
        direction in degrees)."""
        room = self.scene.room
        truth: dict[str, Any] = {
            "seed": self.spec.seed,
            "style": self.spec.style,
            "variant": self.spec.variant,
            "room": {"width": room.width, "depth": room.depth, "height": room.height},
            "camera_height": self.spec.camera_height,
            "objects": [
                {
                    "id": k + 1,
                    "name": obj.name,
                    "kind": obj.kind,
                    "variant": obj.variant,
                    "corners": obj.corners(),
                }
                for k, obj in enumerate(self.scene.objects)
            ],
        }
        if self.spec.camera.tilt_deg > 0:
            truth["camera_tilts"] = {
                grid_key(i, j): self._draw_tilt(position_noise_seed(self.spec.seed, i, j)).degrees()
                for i, j in self.spec.to_grid().indices()
            }
        return truth


@lru_cache(maxsize=8)
def _cos_rows(geometry: PanoramaGeometry) -> NDArray[np.float32]:
    """cos(elevation) of a panorama's rows, (height, 1)."""
    rows = geometry.row_to_elevation(np.arange(geometry.height))
    out = np.cos(rows).astype(np.float32)[:, None]
    out.setflags(write=False)
    return out


@lru_cache(maxsize=4)
def _base(style_name: Style, seed: int, room: Room, grid: Grid) -> Scene:
    return style(style_name).build(seed, room, grid)


def build_world(spec: WorldSpec) -> World:
    """The world of ``spec`` (memoised per process on ``spec.key()``)."""
    key = spec.key()
    if key in _worlds:
        _worlds.move_to_end(key)
        return _worlds[key]
    extent = spec.room_extent
    room = Room(extent.width, extent.depth, extent.height)
    grid = spec.to_grid()
    base = _base(spec.style, spec.seed, room, grid)
    extra = variant_objects(spec.variant, spec.seed, base, grid, spec.camera_height)
    world = World(spec, base.with_objects(extra), len(base.objects))
    _worlds[key] = world
    if len(_worlds) > _CACHE_SIZE:
        _worlds.popitem(last=False)
    return world


def render_position(spec: WorldSpec, i: int, j: int) -> dict[str, NDArray[np.uint8]]:
    """Images of grid position (i, j) with its position noise seed (bit-reproducible)."""
    return build_world(spec).render(spec.pose(i, j), position_noise_seed(spec.seed, i, j))
