"""``database_metadata.yaml``: what homebench reads of it.

BoB robotics' ImageDatabase writes (OpenCV FileStorage YAML)::

    %YAML:1.0
    ---
    metadata:
       time: "2019-01-29 13:05:14"
       type: grid                      # or route
       grid: {beginAtMM: [...], separationMM: [...], size: [nx, ny, nz]}
       camera: {name: pixpro_usb, resolution: [1440, 1440], isPanoramic: 1}
       needsUnwrapping: 1              # raw images; 0: unwrapped panoramas
       isGreyscale: 0

(``grid`` as BoB's ``GridRecorder`` writes it, ``src/navigation/image_database.cc``: the row
labelled (a, b, c), each label below ``size``, gets the position ``beginAtMM + separationMM *
(a, b, c)``, ``GridRecorder::getPosition``), and its unwrapper adds ``unwrapper: {centre:
[0.5, 0.5], inner: 0.1, outer: 0.5, offsetDegrees: 0, flip: 0}`` (centre as fractions of the
width and height, radii as fractions of the height) to the databases it unwraps; a video
database names its ``videoFile``. Other keys (the recorder's git commits, a user's sensors)
are ignored. Where ``needsUnwrapping`` is
missing, ``camera.isPanoramic`` says it, as in BoB.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, model_validator

from homebench.data.bob.filestorage import read_filestorage
from homebench.data.manifest import FloatPair, IntPair

Finite = Annotated[float, Field(allow_inf_nan=False)]
T = TypeVar("T")
#: x, y (and z): BoB writes three values, homebench reads the first two.
_Triple = Annotated[tuple[T, ...], Field(min_length=2, max_length=3)]


class _Loose(BaseModel):
    """Unknown keys ignored; OpenCV's 0 / 1 read as booleans."""

    model_config = ConfigDict(extra="ignore", frozen=True, populate_by_name=True)


class CameraInfo(_Loose):
    """``metadata.camera``: the camera's name and the images' ``resolution`` [width, height]."""

    name: str | None = None
    resolution: IntPair | None = None
    is_panoramic: bool | None = Field(None, alias="isPanoramic")


class GridInfo(_Loose):
    """``metadata.grid``: the recorder's grid, x, y, z (the first two are read). Any key may
    be left out."""

    begin_mm: _Triple[Finite] | None = Field(None, alias="beginAtMM")
    separation_mm: _Triple[Finite] | None = Field(None, alias="separationMM")
    size: _Triple[Annotated[int, Field(ge=1)]] | None = None


class Unwrapper(_Loose):
    """BoB's unwrapping of a raw panoramic image: column j of the unwrapped image samples the
    image angle ``360 j / width + offsetDegrees`` (0 pointing down the image from the centre,
    turning to its left), its rows the radii ``inner`` (top row; ``flip``: bottom) to
    ``outer``. Centre in fractions of the image's width and height, radii of its height."""

    centre: FloatPair
    inner: Finite = Field(ge=0)
    outer: Finite = Field(gt=0)
    offset_deg: Finite = Field(0.0, alias="offsetDegrees")
    flip: bool = False

    @model_validator(mode="after")
    def _ordered(self) -> Unwrapper:
        if self.inner >= self.outer:
            raise ValueError(f"inner ({self.inner:g}) must be below outer ({self.outer:g})")
        return self


class Metadata(_Loose):
    """``metadata``: the keys homebench reads."""

    type: Literal["grid", "route"] | None = None
    grid: GridInfo | None = None
    camera: CameraInfo | None = None
    needs_unwrapping_key: bool | None = Field(None, alias="needsUnwrapping")
    unwrapper: Unwrapper | None = None
    video_file: str | None = Field(None, alias="videoFile")

    @property
    def needs_unwrapping(self) -> bool | None:
        """Whether the images are raw panoramic images (None: the file does not say)."""
        if self.needs_unwrapping_key is not None:
            return self.needs_unwrapping_key
        return self.camera.is_panoramic if self.camera is not None else None

    @property
    def resolution(self) -> tuple[int, int] | None:
        return self.camera.resolution if self.camera is not None else None


class MetadataFile(_Loose):
    metadata: Metadata


def read_metadata(path: Path) -> Metadata | None:
    """The metadata in ``path``; None when there is no such file (BoB reads such databases
    too); ConfigError naming the file and line when it cannot be read as metadata."""
    if not path.exists():
        return None
    return read_filestorage(path, MetadataFile, "database metadata").metadata
