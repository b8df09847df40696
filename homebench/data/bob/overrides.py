"""What a Brains on Board database's metadata does not say, in a manifest's terms.

An optional ``homebench.yaml`` in the database folder, or the same keys given as a
:class:`BobOverrides` (a run config's database entry), states the camera model where the
metadata gives none (unwrapped images: no vertical field of view; raw images: no elevations),
how the headings are written, the order of a grid's labels, what to do with rows without a
pose and the database's name::

    name: antworld-grid                  # default: the folder's name
    description: "Ant World, 1 m grid"
    headings: {zero_deg: 90, direction: cw}   # BoB's compass bearings (the default)
    grid: {order: bob-recorder}          # as-written (default) | transposed | bob-recorder
    missing_poses: interpolate           # skip (default) | interpolate: rows without X, Y or
                                         # Heading (:mod:`.gaps`)
    images:
      unfolded:                          # images that need no unwrapping
        panorama: {elevation_top_deg: 60, elevation_bottom_deg: -15, direction: ccw,
                   zero_column: 0}
      # raw:                             # images that need unwrapping
      #   catadioptric: {centre: [...], radii: [...], elevations_deg: [...], direction: cw,
      #                  zero_angle_deg: -90}

The image sections are the manifest's (``homebench/data/manifest.py``), so ``homebench data
check``'s corrections (``set images.unfolded.panorama.zero_column: ...``) read as keys of this
file; keys a section leaves out keep the database's defaults (:mod:`.camera`), not the
manifest's. ``grid.order`` is the manifest's key (:mod:`homebench.data.grid_order`). A config's
keys replace the file's, top-level key by key.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field

from homebench.data.grid_order import GridOrder
from homebench.data.manifest import CatadioptricSection, Name, PanoramaSection
from homebench.geometry import Direction, HeadingConvention
from homebench.strict import StrictTypesModel
from homebench.yamlio import load_model


class PanoramaOverride(StrictTypesModel):
    """A manifest's panorama section whose keys may be left out: those keep the database's
    defaults (:func:`over`)."""

    elevation_top_deg: float | None = None  # elevation of the upper edge of the first row
    elevation_bottom_deg: float | None = None  # elevation of the lower edge of the last row
    direction: Direction | None = None  # ccw: azimuth grows to the right
    zero_column: float | None = None  # column of azimuth 0 (ahead), in [0, width)

    def over(self, base: Mapping[str, Any]) -> PanoramaSection:
        """The section of the keys ``base`` gives, those given here replacing them;
        ValidationError as a manifest's."""
        return PanoramaSection.model_validate({**base, **self.model_dump(exclude_none=True)})


class UnfoldedOverride(StrictTypesModel):
    """The camera model of images that need no unwrapping."""

    panorama: PanoramaOverride  # the panorama's keys that differ from the database's defaults


class RawOverride(StrictTypesModel):
    """The camera model of images that need unwrapping."""

    catadioptric: CatadioptricSection  # the mirror's model, as a manifest's catadioptric section


class ImageOverrides(StrictTypesModel):
    """The camera model of one image kind (a database holds one)."""

    raw: RawOverride | None = None  # the folder's images need unwrapping
    unfolded: UnfoldedOverride | None = None  # the folder's images are unfolded panoramas


class HeadingsOverride(StrictTypesModel):
    """How ``Heading [degrees]`` is written: ``zero_deg`` is the world direction (degrees, ccw
    from +x) of a heading of 0, ``direction`` the way headings grow seen from above. A key
    left out keeps the default (:data:`~homebench.data.bob.conventions.BOB_HEADINGS`)."""

    # world direction (degrees, ccw from +x) of a heading of 0; None: 90 (BoB's bearings)
    zero_deg: Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)] | None = None
    direction: Direction | None = None  # the way headings grow seen from above; None: BoB's cw

    def over(self, base: HeadingConvention) -> HeadingConvention:
        """``base`` with the keys given here replaced."""
        return HeadingConvention(
            base.zero_deg if self.zero_deg is None else self.zero_deg,
            base.direction if self.direction is None else self.direction,
        )


class GridOverride(StrictTypesModel):
    """How a grid's labels (Grid X, Grid Y) map to the positions its images were taken at."""

    # as-written (the label is the position), transposed or bob-recorder (BoB's recorder order)
    order: GridOrder = "as-written"


#: What to do with rows without a position or heading (:mod:`homebench.data.bob.gaps`).
MissingPoses = Literal["skip", "interpolate"]


class BobOverrides(StrictTypesModel):
    """``homebench.yaml`` of a Brains on Board database: see the module docstring."""

    name: Name | None = None
    description: str | None = None
    headings: HeadingsOverride | None = None
    grid: GridOverride | None = None
    missing_poses: MissingPoses | None = None
    images: ImageOverrides | None = None

    def over(self, base: BobOverrides | None) -> BobOverrides:
        """These overrides over ``base``: each top-level key given here replaces base's."""
        if base is None:
            return self
        given = self.model_dump(exclude_none=True)
        return BobOverrides.model_validate({**base.model_dump(exclude_none=True), **given})


def read_overrides(path: Path) -> BobOverrides | None:
    """The overrides in ``path`` (None when there is no such file); ConfigError naming the file,
    line and key otherwise."""
    if not path.exists():
        return None
    return load_model(BobOverrides, path, what="homebench.yaml")
