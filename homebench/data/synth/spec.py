"""The generator spec of a generated world: everything that determines its images.

A spec is a frozen, validated pydantic model. Its :meth:`WorldSpec.key` (a hash of the canonical
JSON plus the renderer version) names the cache folder, so two specs that differ in any field
never share images, and the same spec always finds its images again.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from homebench.data.synth.camera import CameraSpec
from homebench.geometry import CatadioptricGeometry, Grid, PanoramaGeometry, Pose
from homebench.image_header import size_problem

#: Bump when the renderer changes its output for an unchanged spec (invalidates caches).
RENDERER_VERSION = 2

Variant = Literal["original", "arboreal", "chairs", "day", "twilight", "winlit"]
VARIANTS: tuple[Variant, ...] = ("original", "arboreal", "chairs", "day", "twilight", "winlit")
Style = Literal["posters", "lab", "corridor", "outdoor", "arena"]
STYLES: tuple[Style, ...] = ("posters", "lab", "corridor", "outdoor", "arena")
#: What a world's images show: ``photo``, the lit scene through the camera; ``landmarks``, its
#: ground-truth landmarks (every object black on a white room, no light, no camera).
Render = Literal["photo", "landmarks"]


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class GridSpec(_Frozen):
    """Capture grid: ``shape`` = (nx, ny) positions ``spacing`` metres apart from ``origin``."""

    shape: tuple[int, int] = (10, 17)  # (nx, ny) positions (Vardy's sets: 10 x 17)
    spacing: float = Field(0.30, gt=0)  # metres between neighbouring positions
    # (x, y) metres of position (0, 0); None: the grid centred in the room
    origin: tuple[float, float] | None = None

    @model_validator(mode="after")
    def _positive_shape(self) -> GridSpec:
        if min(self.shape) < 1:
            raise ValueError("grid shape must be at least 1 x 1")
        return self


class RoomSpec(_Frozen):
    """Room extent in metres: x in [0, width], y in [0, depth], z in [0, height].

    Outdoors the "room" is the box of the far scenery (skyline on its walls, sky above).
    """

    width: float = Field(6.0, gt=1)  # extent along x, metres
    depth: float = Field(8.4, gt=1)  # extent along y, metres
    height: float = Field(2.8, gt=1)  # floor to ceiling, metres


#: Each style's room when the spec names none.
STYLE_ROOMS: dict[Style, RoomSpec] = {
    "posters": RoomSpec(width=6.0, depth=8.4, height=2.8),
    "lab": RoomSpec(width=6.6, depth=9.0, height=3.0),
    "corridor": RoomSpec(width=3.6, depth=16.0, height=2.7),
    "outdoor": RoomSpec(width=400.0, depth=400.0, height=150.0),
    "arena": RoomSpec(width=7.0, depth=9.0, height=3.0),
}


class RawImageSpec(_Frozen):
    """Raw catadioptric image, Bielefeld format by default (equiangular mirror model)."""

    width: int = Field(752, ge=32)  # image width, pixels (the mirror centred in the image)
    height: int = Field(564, ge=32)  # image height, pixels
    inner_radius: float = Field(25.0, ge=0)  # radius (px) of the mirror image's inner edge
    outer_radius: float = Field(270.0, gt=0)  # radius (px) of its outer edge
    # elevation imaged at the inner radius, degrees (linear in the radius in between)
    elevation_inner_deg: float = Field(-50.0, gt=-90, lt=0)
    elevation_outer_deg: float = Field(45.0, gt=0, lt=90)  # elevation imaged at the outer radius
    direction: Literal["ccw", "cw"] = "cw"  # which way azimuth grows on screen
    zero_angle_deg: float = 90.0  # image angle (ccw from +u) where azimuth 0 (ahead) appears

    @model_validator(mode="after")
    def _bounded(self) -> RawImageSpec:
        problem = size_problem(self.width, self.height)
        if problem:
            raise ValueError(problem)
        return self

    def geometry(self) -> CatadioptricGeometry:
        return CatadioptricGeometry(
            width=self.width,
            height=self.height,
            centre=((self.width - 1) / 2.0, (self.height - 1) / 2.0),
            radii=(self.inner_radius, self.outer_radius),
            elevations=(
                math.radians(self.elevation_inner_deg),
                math.radians(self.elevation_outer_deg),
            ),
            direction=self.direction,
            zero_angle=math.radians(self.zero_angle_deg),
        )


class UnfoldedImageSpec(_Frozen):
    """Unfolded panorama; its height follows from square pixels over the elevation range."""

    width: int = Field(360, ge=16)  # panorama columns, pixels (one per degree by default)
    elevation_top_deg: float = Field(45.0, gt=0, lt=90)  # elevation of the top edge, degrees
    elevation_bottom_deg: float = Field(-50.0, gt=-90, lt=0)  # of the bottom edge, degrees

    @model_validator(mode="after")
    def _bounded(self) -> UnfoldedImageSpec:
        problem = size_problem(self.width, self.height)
        if problem:
            raise ValueError(f"width {self.width}: {problem}")
        return self

    @property
    def height(self) -> int:
        span = self.elevation_top_deg - self.elevation_bottom_deg
        return max(1, round(self.width * span / 360.0))

    def geometry(self) -> PanoramaGeometry:
        return PanoramaGeometry(
            width=self.width,
            height=self.height,
            elevation_top=math.radians(self.elevation_top_deg),
            elevation_bottom=math.radians(self.elevation_bottom_deg),
        )


class WorldSpec(_Frozen):
    """A generated world: a seeded place of one ``style``, one variant of it, a capture grid,
    the two image geometries and the camera that takes them.

    ``room`` None takes the style's room (:data:`STYLE_ROOMS`). ``light_gain`` multiplies all
    scene radiance (a pure global change of the light, for testing the camera's exposure).
    ``render`` ``landmarks`` renders the world's ground-truth landmarks instead of photographs
    (:data:`Render`); it enters the key only when set, so photo worlds keep their keys.
    """

    # seeds the place (its objects, the variant's additions, the sun) and each image's noise
    seed: int = Field(0, ge=0)
    style: Style = "posters"  # the kind of place: posters, lab, corridor, outdoor, arena
    # original, arboreal (a tall plant), chairs, day, twilight or winlit (Vardy's variants)
    variant: Variant = "original"
    room: RoomSpec | None = None  # the room's extent; None: the style's room
    grid: GridSpec = GridSpec()  # the capture grid
    camera_height: float = Field(1.0, gt=0)  # height of the camera above the floor, metres
    heading_deg: float = 0.0  # heading of every grid view, degrees ccw from +x
    raw: RawImageSpec = RawImageSpec()  # the raw catadioptric images' geometry
    unfolded: UnfoldedImageSpec = UnfoldedImageSpec()  # the unfolded panoramas' geometry
    camera: CameraSpec = CameraSpec()  # optics, exposure, sensor and response of the camera
    light_gain: float = Field(1.0, gt=0)  # multiplies all scene radiance (a global light change)
    # photo: the lit scene through the camera; landmarks: objects black on a white room
    render: Render = "photo"

    @model_validator(mode="after")
    def _grid_fits_room(self) -> WorldSpec:
        g, room = self.to_grid(), self.room_extent
        far = g.position(g.shape[0] - 1, g.shape[1] - 1)
        if min(g.origin) <= 0 or far[0] >= room.width or far[1] >= room.depth:
            raise ValueError("the capture grid must lie inside the room")
        if not 0 < self.camera_height < room.height:
            raise ValueError("camera_height must be between floor and ceiling")
        return self

    @model_validator(mode="after")
    def _tilt_photographs_only(self) -> WorldSpec:
        if self.render == "landmarks" and self.camera.tilt_deg > 0:
            raise ValueError("camera.tilt_deg applies to photographs; landmark images are upright")
        return self

    @property
    def room_extent(self) -> RoomSpec:
        """The room in metres: ``room`` or the style's."""
        return self.room if self.room is not None else STYLE_ROOMS[self.style]

    def to_grid(self) -> Grid:
        if self.grid.origin is not None:
            return Grid(self.grid.shape, self.grid.spacing, self.grid.origin)
        nx, ny = self.grid.shape
        room = self.room_extent
        x0 = (room.width - (nx - 1) * self.grid.spacing) / 2.0
        y0 = (room.depth - (ny - 1) * self.grid.spacing) / 2.0
        return Grid(self.grid.shape, self.grid.spacing, (x0, y0))

    def pose(self, i: int, j: int) -> Pose:
        return self.to_grid().pose(i, j, math.radians(self.heading_deg))

    def canonical_data(self) -> dict[str, Any]:
        """The spec as JSON data: every field, but those of :data:`KEYED_WHEN_SET` only when
        they differ from their defaults, so that specs older than them keep their keys and a
        generated set's manifest stays readable by the homebench that wrote its kind before."""
        data = self.model_dump(mode="json")
        _drop_defaults(data, KEYED_WHEN_SET)
        return data

    def canonical_json(self) -> str:
        """:meth:`canonical_data` as sorted, compact JSON."""
        return json.dumps(self.canonical_data(), sort_keys=True, separators=(",", ":"))

    def key(self) -> str:
        """Stable 16-hex-digit hash of the spec and the renderer version."""
        payload = f"renderer={RENDERER_VERSION};{self.canonical_json()}".encode()
        return hashlib.sha256(payload).hexdigest()[:16]


#: Fields added after worlds were shipped, with the defaults that leave them out of
#: :meth:`WorldSpec.canonical_json` (nested: a section's fields).
KEYED_WHEN_SET: dict[str, Any] = {
    "render": "photo",
    "camera": {"noise": True, "tilt_deg": 0.0},
}


def _drop_defaults(data: dict[str, Any], defaults: dict[str, Any]) -> None:
    """Remove from ``data`` (in place) every field of ``defaults`` that holds its default."""
    for name, default in defaults.items():
        if isinstance(default, dict):
            _drop_defaults(data[name], default)
        elif data.get(name) == default:
            del data[name]
