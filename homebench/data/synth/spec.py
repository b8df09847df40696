"""The generator spec of a generated world: everything that determines its images.

A spec is a frozen, validated pydantic model. Its :meth:`WorldSpec.key` (a hash of the canonical
JSON plus the renderer version) names the cache folder, so two specs that differ in any field
never share images, and the same spec always finds its images again.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from homebench.geometry import CatadioptricGeometry, Grid, PanoramaGeometry, Pose

#: Bump when the renderer changes its output for an unchanged spec (invalidates caches).
RENDERER_VERSION = 1

Variant = Literal["original", "arboreal", "chairs", "day", "twilight", "winlit"]
VARIANTS: tuple[Variant, ...] = ("original", "arboreal", "chairs", "day", "twilight", "winlit")


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class GridSpec(_Frozen):
    """Capture grid: ``shape`` = (nx, ny) positions ``spacing`` metres apart from ``origin``."""

    shape: tuple[int, int] = (10, 17)
    spacing: float = Field(0.30, gt=0)
    origin: tuple[float, float] | None = None  # None: centred in the room

    @model_validator(mode="after")
    def _positive_shape(self) -> GridSpec:
        if min(self.shape) < 1:
            raise ValueError("grid shape must be at least 1 x 1")
        return self


class RoomSpec(_Frozen):
    """Room extent in metres: x in [0, width], y in [0, depth], z in [0, height]."""

    width: float = Field(6.0, gt=1)
    depth: float = Field(8.4, gt=1)
    height: float = Field(2.8, gt=1)


class RawImageSpec(_Frozen):
    """Raw catadioptric image, Bielefeld format by default (equiangular mirror model)."""

    width: int = Field(752, ge=32)
    height: int = Field(564, ge=32)
    inner_radius: float = Field(25.0, ge=0)
    outer_radius: float = Field(270.0, gt=0)
    elevation_inner_deg: float = Field(-50.0, gt=-90, lt=0)
    elevation_outer_deg: float = Field(45.0, gt=0, lt=90)
    direction: Literal["ccw", "cw"] = "cw"
    zero_angle_deg: float = 90.0

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

    width: int = Field(360, ge=16)
    elevation_top_deg: float = Field(45.0, gt=0, lt=90)
    elevation_bottom_deg: float = Field(-50.0, gt=-90, lt=0)

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
    """A generated world: a seeded room, one variant of it, a capture grid and two cameras."""

    seed: int = Field(0, ge=0)
    variant: Variant = "original"
    room: RoomSpec = RoomSpec()
    grid: GridSpec = GridSpec()
    camera_height: float = Field(1.0, gt=0)
    heading_deg: float = 0.0
    raw: RawImageSpec = RawImageSpec()
    unfolded: UnfoldedImageSpec = UnfoldedImageSpec()
    noise_sigma: float = Field(1.0, ge=0)  # sensor noise, grey levels (0..255); variants scale it

    @model_validator(mode="after")
    def _grid_fits_room(self) -> WorldSpec:
        g = self.to_grid()
        far = g.position(g.shape[0] - 1, g.shape[1] - 1)
        if min(g.origin) <= 0 or far[0] >= self.room.width or far[1] >= self.room.depth:
            raise ValueError("the capture grid must lie inside the room")
        if not 0 < self.camera_height < self.room.height:
            raise ValueError("camera_height must be between floor and ceiling")
        return self

    def to_grid(self) -> Grid:
        if self.grid.origin is not None:
            return Grid(self.grid.shape, self.grid.spacing, self.grid.origin)
        nx, ny = self.grid.shape
        x0 = (self.room.width - (nx - 1) * self.grid.spacing) / 2.0
        y0 = (self.room.depth - (ny - 1) * self.grid.spacing) / 2.0
        return Grid(self.grid.shape, self.grid.spacing, (x0, y0))

    def pose(self, i: int, j: int) -> Pose:
        return self.to_grid().pose(i, j, math.radians(self.heading_deg))

    def canonical_json(self) -> str:
        return json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))

    def key(self) -> str:
        """Stable 16-hex-digit hash of the spec and the renderer version."""
        payload = f"renderer={RENDERER_VERSION};{self.canonical_json()}".encode()
        return hashlib.sha256(payload).hexdigest()[:16]
