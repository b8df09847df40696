"""What a Brains on Board database's metadata does not say, in a manifest's terms.

An optional ``homebench.yaml`` in the database folder, or the same keys given as a
:class:`BobOverrides` (a run config's database entry), states the camera model where the
metadata gives none (unwrapped images: no vertical field of view; raw images: no elevations)
and the database's name::

    name: antworld-grid                  # default: the folder's name
    description: "Ant World, 1 m grid"
    images:
      unfolded:                          # images that need no unwrapping
        panorama: {elevation_top_deg: 60, elevation_bottom_deg: -15, direction: ccw,
                   zero_column: 0}
      # raw:                             # images that need unwrapping
      #   catadioptric: {centre: [...], radii: [...], elevations_deg: [...], direction: cw,
      #                  zero_angle_deg: -90}

The sections are the manifest's (``homebench/data/manifest.py``), so ``homebench data check``'s
corrections (``set images.unfolded.panorama.zero_column: ...``) read as keys of this file. A
config's keys replace the file's, top-level key by key.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict

from homebench.data.manifest import CatadioptricSection, Name, PanoramaSection
from homebench.yamlio import load_model


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)


class UnfoldedOverride(_Strict):
    panorama: PanoramaSection


class RawOverride(_Strict):
    catadioptric: CatadioptricSection


class ImageOverrides(_Strict):
    """The camera model of one image kind (a database holds one)."""

    raw: RawOverride | None = None
    unfolded: UnfoldedOverride | None = None


class BobOverrides(_Strict):
    """``homebench.yaml`` of a Brains on Board database: see the module docstring."""

    name: Name | None = None
    description: str | None = None
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
