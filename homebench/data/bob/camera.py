"""The camera model of a Brains on Board database: what its metadata says, what the overrides
(``homebench.yaml``, a config) say, and what is assumed where neither says.

- **Unwrapped images** (``needsUnwrapping: 0``): the metadata gives neither the vertical field
  of view nor the column of the heading. For BoB's Ant World renders (``camera.name:
  opengl``) they are the renderer's (:mod:`.conventions`: +60 to -15 deg, the heading at
  column W/2 - 0.5, azimuths shrinking to the right). For any other camera, assumed: the
  horizon at the middle row, rows as tall as columns are wide (a 720 x 150 image spans
  +-37.5 deg) and azimuth 0 at column 0, growing to the right (a manifest's defaults). Keys of
  ``images.unfolded.panorama`` replace them one by one; one note names those assumed.
- **Raw images** (``needsUnwrapping: 1``): BoB's ``unwrapper`` gives the centre, the inner and
  outer radius and the image angle it unwraps to column 0, not elevations. Assumed: the horizon
  halfway between the radii, pixels as tall as wide there, and the azimuths of BoB's unwrapped
  columns under the assumption above (so a raw database and its unwrapped copy agree). Without
  an unwrapper nothing can be assumed: an error says what to add.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from pydantic import ValidationError

from homebench.data.bob.conventions import ANT_WORLD_CAMERA, ant_world_panorama
from homebench.data.bob.metadata import Metadata, Unwrapper
from homebench.data.bob.overrides import BobOverrides, ImageOverrides, PanoramaOverride
from homebench.data.manifest import (
    KINDS,
    CatadioptricSection,
    PanoramaSection,
    RawImages,
    UnfoldedImages,
)
from homebench.errors import DataError
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry, wrap_angle
from homebench.views import ImageKind

Model = PanoramaGeometry | CatadioptricGeometry


@dataclass(frozen=True)
class Camera:
    """The images' ``kind``, camera model and ``notes`` on what was assumed."""

    kind: ImageKind
    geometry: Model
    notes: tuple[str, ...] = ()


def camera_model(
    metadata: Metadata | None,
    overrides: BobOverrides,
    size: tuple[int, int],
    metadata_name: str,
    overrides_name: str,
) -> Camera:
    """The camera of images of ``size`` [width, height] described by ``metadata`` (read from
    ``metadata_name``; None: no metadata) and ``overrides`` (from ``overrides_name``)."""
    images = overrides.images or ImageOverrides()
    given = [kind for kind in KINDS if getattr(images, kind) is not None]
    if len(given) > 1:
        raise DataError(f"{overrides_name}: images: give one of raw and unfolded, not both")
    needs = metadata.needs_unwrapping if metadata is not None else None
    stated: ImageKind | None = None if needs is None else ("raw" if needs else "unfolded")
    if given and stated is not None and given[0] != stated:
        raise DataError(
            f"{overrides_name}: images.{given[0]}: {metadata_name} says needsUnwrapping: "
            f"{int(bool(needs))}: describe the images as images.{stated}"
        )
    notes = []
    if stated is None and not given:
        notes.append(
            f"{metadata_name} does not say whether the images need unwrapping "
            "(needsUnwrapping): read as unwrapped panoramas"
        )
    if images.raw is not None:
        raw = images.raw.catadioptric
        where = f"{overrides_name}: images.raw"
        return Camera(
            "raw", _checked(lambda: RawImages(size=size, catadioptric=raw), where), tuple(notes)
        )
    if stated == "raw":
        assert metadata is not None
        geometry, note = _unwrapped_by_bob(metadata, size, metadata_name, overrides_name)
        return Camera("raw", geometry, (*notes, note))
    given_panorama = images.unfolded.panorama if images.unfolded is not None else None
    geometry, note = _panorama(metadata, given_panorama, size, metadata_name, overrides_name)
    return Camera("unfolded", geometry, (*notes, note) if note else tuple(notes))


def _panorama(
    metadata: Metadata | None,
    given: PanoramaOverride | None,
    size: tuple[int, int],
    metadata_name: str,
    overrides_name: str,
) -> tuple[PanoramaGeometry, str | None]:
    """The camera model of unwrapped images: the keys ``given`` (images.unfolded.panorama)
    over the database's defaults, and the note naming the defaults used (None: none)."""
    stated = given.model_dump(exclude_none=True) if given is not None else {}
    missing = [key for key in PanoramaOverride.model_fields if key not in stated]
    camera = metadata.camera.name if metadata is not None and metadata.camera else None
    ant_world = camera == ANT_WORLD_CAMERA
    default = ant_world_panorama(size) if ant_world else _square_panorama(size)
    if default is None and {"elevation_top_deg", "elevation_bottom_deg"} & set(missing):
        width, height = size
        raise DataError(
            f"{metadata_name}: unwrapped images of {width} x {height} px are too tall for a "
            "panorama of square pixels (over 180 deg): give images.unfolded.panorama "
            f"(elevation_top_deg, elevation_bottom_deg) in {overrides_name}"
        )
    base = (
        PanoramaSection.from_geometry(default).model_dump()
        if default is not None
        else {"direction": "ccw", "zero_column": 0.0}
    )
    where = f"{overrides_name}: images.unfolded.panorama"
    panorama = _checked(
        lambda: UnfoldedImages(size=size, panorama=(given or PanoramaOverride()).over(base)),
        where,
    )
    assert isinstance(panorama, PanoramaGeometry)
    if not missing:
        return panorama, None
    assumed = ", ".join(f"{key} {_value(base[key])}" for key in missing)
    source = (
        f"camera {ANT_WORLD_CAMERA!r}: read as BoB's Ant World renders (rows from +60 to -15 "
        "deg, the heading between the middle two columns, bearings growing to the right; "
        "homebench/data/bob/conventions.py)"
        if ant_world
        else "gives no vertical field of view or column of the heading: assumed the horizon "
        "at the middle row, rows as tall as columns are wide and the heading at column 0, "
        "azimuths growing to the right"
    )
    return panorama, (
        f"{metadata_name}: {source}: images.unfolded.panorama {assumed}; "
        f"{overrides_name} sets them (`homebench data check` measures them)"
    )


def _square_panorama(size: tuple[int, int]) -> PanoramaGeometry | None:
    """The panorama of ``size`` with the horizon at the middle row, square pixels and the
    heading at column 0, azimuths growing to the right; None when over 180 deg tall."""
    width, height = size
    half = math.pi * height / width
    return PanoramaGeometry(width, height, half, -half) if half <= math.pi / 2 else None


def _value(value: object) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _checked(section: Callable[[], RawImages | UnfoldedImages], where: str) -> Model:
    """The camera model of the image section ``section()`` builds and validates (as a
    manifest's); DataError starting with ``where`` and the reasons otherwise."""
    try:
        return section().geometry()
    except ValidationError as error:
        reasons = [e["msg"].removeprefix("Value error, ") for e in error.errors()]
        raise DataError(f"{where}: {'; '.join(reasons)}") from None
    except ValueError as error:
        raise DataError(f"{where}: {error}") from None


def _unwrapped_by_bob(
    metadata: Metadata, size: tuple[int, int], metadata_name: str, overrides_name: str
) -> tuple[CatadioptricGeometry, str]:
    """The raw camera model that the metadata's unwrapper implies, and the note saying what it
    assumes; DataError saying what to add where the metadata has no unwrapper."""
    if metadata.unwrapper is None:
        name = metadata.camera.name if metadata.camera is not None else None
        raise DataError(
            f"{metadata_name}: raw images (needsUnwrapping: 1) of camera {name or '(unnamed)'}, "
            "but no unwrapper (centre, inner, outer, offsetDegrees, flip) says where the "
            "panorama lies in them: add images.raw.catadioptric (centre, radii, elevations_deg, "
            f"direction, zero_angle_deg) to {overrides_name}, or BoB's unwrapper of the camera "
            "to the metadata"
        )
    unwrapper = metadata.unwrapper
    where = f"{metadata_name}: metadata.unwrapper"
    geometry = _checked(
        lambda: RawImages(
            size=size,
            catadioptric=CatadioptricSection.from_geometry(from_unwrapper(unwrapper, size)),
        ),
        where,
    )
    assert isinstance(geometry, CatadioptricGeometry)
    top, bottom = max(geometry.elevations), min(geometry.elevations)
    note = (
        f"{metadata_name}: the unwrapper gives no elevations: assumed the horizon halfway "
        f"between its radii ({geometry.horizon_radius:.1f} px), pixels as tall as wide there "
        f"({math.degrees(top):+.1f} to {math.degrees(bottom):+.1f} deg) and azimuth 0 where "
        f"it unwraps column 0, growing clockwise; images.raw.catadioptric in {overrides_name} "
        "sets them"
    )
    return geometry, note


def from_unwrapper(unwrapper: Unwrapper, size: tuple[int, int]) -> CatadioptricGeometry:
    """The raw camera model of BoB's ``unwrapper`` on images of ``size`` [width, height].

    BoB puts the centre at (round(width cx), round(height cy)) px, the radii at round(height r)
    px, and unwraps column j of a w-wide panorama from the pixels at ``centre + r (-sin t,
    cos t)``, ``t = 360 j / w + offsetDegrees``: image angle (ccw from +u, v down) ``-90 - t``.
    With azimuth 0 at column 0 growing to the right (the assumption for unwrapped images),
    azimuth a is t = a + offset: clockwise on the image from ``-90 - offset``. Row 0 (the top,
    up) samples the inner radius, the bottom row the outer (``flip``: the reverse); elevations
    as described in the module docstring.
    """
    width, height = size
    centre = (_round(width * unwrapper.centre[0]), _round(height * unwrapper.centre[1]))
    inner, outer = _round(height * unwrapper.inner), _round(height * unwrapper.outer)
    if inner >= outer:
        raise ValueError(
            f"inner and outer radius are {inner:g} and {outer:g} px on a {height} px high "
            "image: no annulus"
        )
    half = (outer - inner) / (inner + outer)  # (outer - inner) / mid-radius / 2, radians
    elevations = (-half, half) if unwrapper.flip else (half, -half)
    zero = float(wrap_angle(math.radians(-90.0 - unwrapper.offset_deg)))
    return CatadioptricGeometry(width, height, centre, (inner, outer), elevations, "cw", zero)


def _round(value: float) -> float:
    """``value`` rounded half away from zero, as C's round."""
    return float(math.copysign(math.floor(abs(value) + 0.5), value))
