"""Database manifests: one YAML schema for real, generated and user-made grid databases.

A manifest says what a folder of grid images is: the grid, the shared heading, and for each image
kind ("raw" catadioptric, "unfolded" panorama) where the files are, their size, the camera model
and, where known, each file's sha256. A generated set adds the generator's spec. Angles are in
degrees in YAML and converted to geometry.py's radians by :meth:`Manifest.geometry` and
:meth:`Manifest.heading`.

Validation is strict: unknown keys, wrong types and bad values raise ConfigError naming the file,
the line and the key path (``images.raw.size[0]``). The heading has no default (a wrong one
turns every home direction; ``homebench data check`` tests the conventions against the images),
a zero column lies on the image, a centre in it, angles and elevations in their ranges.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
import math
import posixpath
import re
import string
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import (
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    field_validator,
    model_serializer,
    model_validator,
)

from homebench.data.grid_order import GridOrder, label_of, position_shape
from homebench.data.synth.spec import WorldSpec
from homebench.errors import ConfigError, DataError
from homebench.fileio import read_small_text
from homebench.geometry import CatadioptricGeometry, Grid, PanoramaGeometry, parse_grid_key
from homebench.image_header import size_problem
from homebench.strict import StrictTypesModel
from homebench.views import ImageKind
from homebench.yamlio import MAX_YAML_BYTES, parse_model

SCHEMA_VERSION = 1
KINDS: tuple[ImageKind, ...] = ("raw", "unfolded")
#: Most grid positions of one database (1000 x 1000; Vardy's sets have 170): every position is
#: looked at when a database is checked, so the grid bounds the work a manifest can ask for.
MAX_GRID_POSITIONS = 1_000_000
#: Widest index field of a file name pattern ({x:09d}). A width is memory: {x:>2000000000} made
#: a 2 GB file name; grid indices (below MAX_GRID_POSITIONS) never need more than 7 digits.
MAX_FIELD_WIDTH = 9
#: The format spec of an index field: empty or "d", with a width 1..MAX_FIELD_WIDTH, optionally
#: zero-padded ({x}, {x:d}, {x:3}, {x:03d}); no fill, alignment, sign, precision or type.
_INDEX_SPEC = re.compile(rf"(0?[1-{MAX_FIELD_WIDTH}])?d?")

# YAML gives lists; tuples accept them (the items stay strict).
IntPair = Annotated[tuple[int, int], Field(strict=False)]
FloatPair = Annotated[tuple[float, float], Field(strict=False)]
FloatSeq = Annotated[tuple[float, ...], Field(strict=False, min_length=2)]
Sha256 = Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]
Fingerprint = Annotated[str, Field(pattern=r"^[0-9]{1,9}:[0-9]{1,9}:[0-9a-f]{66}$")]
Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$")]
Direction = Literal["ccw", "cw"]


def _relative_posix(value: str, what: str) -> str:
    """Check that ``value`` is a relative path inside the database root; return it normalised."""
    norm = posixpath.normpath(value)
    if (
        value.startswith("/")
        or _has_control_or_backslash(value)
        or norm == ".."
        or norm.startswith("../")
    ):
        raise ValueError(f"{what} must be a relative path inside the database folder: {value!r}")
    return norm


_CONTROL_OR_BACKSLASH = re.compile(r"[\x00-\x1f\x7f\\]")


def _has_control_or_backslash(text: str) -> bool:
    return _CONTROL_OR_BACKSLASH.search(text) is not None


def outside_problem(name: str) -> str | None:
    """Why the relative file name ``name`` might not stay inside its folder, or None.

    A safe name has no control character or backslash and no empty, "." or ".." component, so
    that joining it to a folder and normalising the result never leaves the folder.
    """
    if _has_control_or_backslash(name):
        return "has a control character or a backslash"
    if any(part in ("", ".", "..") for part in name.split("/")):
        return "has an empty, '.' or '..' path component (or starts with '/')"
    return None


def _field_text(field: str, spec: str, conversion: str | None) -> str:
    """A replacement field as written in a pattern: {x!s:.0}."""
    conversion = f"!{conversion}" if conversion else ""
    return f"{{{field}{conversion}{':' if spec else ''}{spec}}}"


class Source(StrictTypesModel):
    """Where a real set comes from and which environment variable points at a local copy."""

    citation: str  # how to cite the set
    url: str | None = None  # where to get it
    # environment variable holding the folder of a local copy (or give --path)
    path_env: Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$")] | None = None


class GridSection(StrictTypesModel):
    """The capture grid: labels (X, Y: a file name's, a ``headings_deg`` key) spanning
    ``shape`` = [nx, ny], the positions ``spacing`` metres apart. ``order`` says at which
    position each label's image was taken (:mod:`homebench.data.grid_order`): as written, the
    label is the position; a transposed grid's positions span [ny, nx]. ``order`` is left out
    of what is written when it is the default, so that manifests and their identities stay as
    they were."""

    shape: IntPair  # [nx, ny]: how many labels along x and y
    spacing: float = Field(gt=0)  # metres between neighbouring positions
    origin: FloatPair = (0.0, 0.0)  # [x, y] metres of position (0, 0)
    # which position each label's image was taken at: as-written, transposed or bob-recorder
    order: GridOrder = "as-written"

    @field_validator("shape")
    @classmethod
    def _positive(cls, shape: tuple[int, int]) -> tuple[int, int]:
        if min(shape) < 1:
            raise ValueError(f"grid shape must be at least [1, 1], got {list(shape)}")
        if shape[0] * shape[1] > MAX_GRID_POSITIONS:
            raise ValueError(
                f"grid shape {list(shape)} has {shape[0] * shape[1]:,} positions; "
                f"at most {MAX_GRID_POSITIONS:,} positions are allowed"
            )
        return shape

    @model_serializer(mode="wrap")
    def _without_default_order(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        if self.order == "as-written":
            data.pop("order", None)
        return data

    def to_grid(self) -> Grid:
        """The positions' grid."""
        return Grid(position_shape(self.order, self.shape), self.spacing, self.origin)

    def label(self, i: int, j: int) -> tuple[int, int]:
        """The label (X, Y) of the image taken at grid position (i, j)."""
        return label_of(self.order, (i, j), position_shape(self.order, self.shape))

    def label_grid(self) -> Grid:
        """The grid the labels span (of the positions' spacing and origin)."""
        return Grid(self.shape, self.spacing, self.origin)


class CatadioptricSection(StrictTypesModel):
    """Raw-image camera model (see geometry.CatadioptricGeometry), angles in degrees."""

    centre: FloatPair  # pixel coordinates of the mirror axis
    radii: FloatSeq  # radial profile: radii (px), increasing ...
    elevations_deg: FloatSeq  # ... and the elevation imaged at each (linear in between)
    direction: Direction = "ccw"  # which way azimuth grows on screen
    zero_angle_deg: float = 0.0  # image angle (ccw from +u) where azimuth 0 (ahead) appears

    @field_validator("zero_angle_deg")
    @classmethod
    def _an_angle(cls, value: float) -> float:
        if not -360.0 <= value <= 360.0:
            raise ValueError(
                f"{value} is no image angle in degrees (ccw from +u): give one in [-360, 360]"
            )
        return value

    @field_validator("elevations_deg")
    @classmethod
    def _elevations(cls, values: tuple[float, ...]) -> tuple[float, ...]:
        return _elevations_in_range(values)

    def geometry(self, size: tuple[int, int]) -> CatadioptricGeometry:
        return CatadioptricGeometry(
            width=size[0],
            height=size[1],
            centre=self.centre,
            radii=self.radii,
            elevations=tuple(math.radians(e) for e in self.elevations_deg),
            direction=self.direction,
            zero_angle=math.radians(self.zero_angle_deg),
        )

    @classmethod
    def from_geometry(cls, g: CatadioptricGeometry) -> CatadioptricSection:
        return cls(
            centre=g.centre,
            radii=g.radii,
            elevations_deg=tuple(_degrees(e) for e in g.elevations),
            direction=g.direction,
            zero_angle_deg=_degrees(g.zero_angle),
        )


class PanoramaSection(StrictTypesModel):
    """Unfolded-panorama camera model (see geometry.PanoramaGeometry), angles in degrees."""

    elevation_top_deg: float  # elevation of the upper edge of the first row
    elevation_bottom_deg: float  # elevation of the lower edge of the last row
    direction: Direction = "ccw"  # ccw: azimuth grows to the right
    zero_column: float = 0.0  # column of azimuth 0 (ahead), in [0, width)

    @field_validator("elevation_top_deg", "elevation_bottom_deg")
    @classmethod
    def _elevation(cls, value: float) -> float:
        return _elevations_in_range((value,))[0]

    def geometry(self, size: tuple[int, int]) -> PanoramaGeometry:
        return PanoramaGeometry(
            width=size[0],
            height=size[1],
            elevation_top=math.radians(self.elevation_top_deg),
            elevation_bottom=math.radians(self.elevation_bottom_deg),
            direction=self.direction,
            zero_column=self.zero_column,
        )

    @classmethod
    def from_geometry(cls, g: PanoramaGeometry) -> PanoramaSection:
        return cls(
            elevation_top_deg=_degrees(g.elevation_top),
            elevation_bottom_deg=_degrees(g.elevation_bottom),
            direction=g.direction,
            zero_column=g.zero_column,
        )


def _elevations_in_range(values: tuple[float, ...]) -> tuple[float, ...]:
    """``values`` if each is an elevation in degrees, in [-90, 90]; else ValueError."""
    for value in values:
        if not -90.0 <= value <= 90.0:
            raise ValueError(f"{value} is no elevation in degrees: give one in [-90, 90]")
    return values


def _degrees(radians: float) -> float:
    """Degrees rounded to 1e-9 deg, so that a round trip through radians gives back 45.0."""
    return round(math.degrees(radians), 9)


class ImageSection(StrictTypesModel):
    """Where one kind of image lives (base of RawImages and UnfoldedImages).

    Files are ``folder``/``pattern`` per grid position, all of one ``size`` [width, height].

    ``pattern`` has the fields {x} and {y} (the grid index, with at most a width, optionally
    zero-padded: {x:02d}, {x:3}) and optionally {ext} (no spec), tried in the order of
    ``extensions``; it may name subfolders ("row{y}/{x}.png") but never a '.', '..' or empty
    component, so that no file name it makes can leave ``folder``. ``files`` maps file names
    (relative to ``folder``) to their sha256, or null where unknown; ``fingerprints`` (optional,
    written for generated sets) to their content fingerprint, which a file made on another
    processor must match where its bytes differ (:mod:`homebench.data.fingerprint`).
    """

    folder: str = "."  # the images' folder, relative to the database root
    # file name per grid index: {x} and {y} (with an optional width: {x:02d}), optionally {ext}
    pattern: str = "{x}_{y}.{ext}"
    # the {ext} values tried, in order (letters and digits, no dot)
    extensions: Annotated[tuple[str, ...], Field(strict=False, min_length=1)] = ("png",)
    size: IntPair  # [width, height] pixels, the same for every image
    files: dict[str, Sha256 | None] = {}  # file name (relative to folder) -> sha256; null: unknown
    # file name -> content fingerprint a file made on another processor must match
    fingerprints: dict[str, Fingerprint] = {}

    @field_validator("folder")
    @classmethod
    def _folder_inside(cls, folder: str) -> str:
        return _relative_posix(folder, "folder")

    @field_validator("extensions")
    @classmethod
    def _plain_extensions(cls, extensions: tuple[str, ...]) -> tuple[str, ...]:
        for ext in extensions:
            if not re.fullmatch(r"[A-Za-z0-9]+", ext):
                raise ValueError(f"an extension is letters and digits without a dot, got {ext!r}")
        return extensions

    @field_validator("pattern")
    @classmethod
    def _pattern_fields(cls, pattern: str) -> str:
        try:
            parts = list(string.Formatter().parse(pattern))
        except ValueError as error:
            raise ValueError(
                f"pattern {pattern!r} is not a valid file name pattern: {error}"
            ) from None
        fields = {field for _, field, _, _ in parts if field is not None}
        if not {"x", "y"} <= fields or not fields <= {"x", "y", "ext"}:
            raise ValueError(f"pattern {pattern!r} must use {{x}} and {{y}}, and may use {{ext}}")
        for _, field, spec, conversion in parts:
            if field is None:
                continue
            plain = conversion is None and (
                _INDEX_SPEC.fullmatch(spec) if field != "ext" else spec == ""
            )
            if not plain:
                raise ValueError(
                    f"pattern {pattern!r}: {_field_text(field, spec, conversion)} is not allowed; "
                    f"use {{x}} and {{y}}, with at most a width of 1 to {MAX_FIELD_WIDTH} "
                    "(zero-padded as in {x:02d}), and {ext}"
                )
        problem = outside_problem(pattern)
        if problem is not None:
            raise ValueError(f"pattern {pattern!r} {problem}")
        return pattern

    @field_validator("size")
    @classmethod
    def _positive_size(cls, size: tuple[int, int]) -> tuple[int, int]:
        if min(size) < 1:
            raise ValueError(f"image size [width, height] must be positive, got {list(size)}")
        problem = size_problem(*size)
        if problem:
            raise ValueError(problem)
        return size

    @model_validator(mode="after")
    def _files_match_pattern(self) -> ImageSection:
        for key, names in (("files", self.files), ("fingerprints", self.fingerprints)):
            for name in names:
                if self.parse_name(name) is None:
                    raise ValueError(f"{key}: {name!r} does not match the pattern {self.pattern!r}")
        return self

    @property
    def uses_ext(self) -> bool:
        return any(f == "ext" for _, f, _, _ in string.Formatter().parse(self.pattern))

    def file_names(self, i: int, j: int) -> list[str]:
        """Candidate file names (relative to ``folder``) of grid position (i, j), in order.

        Each name is checked to stay inside ``folder`` (DataError otherwise), whatever the
        pattern: validation already guarantees it, this makes sure of it where files are named.
        """
        extensions = self.extensions if self.uses_ext else self.extensions[:1]
        names = [self.pattern.format(x=i, y=j, ext=ext) for ext in extensions]
        for name in names:
            problem = outside_problem(name)
            if problem is not None:
                raise DataError(
                    f"{name!r} (pattern {self.pattern!r}) {problem}: it could lie outside "
                    f"the folder {self.folder!r}"
                )
        return names

    def relative_path(self, name: str) -> str:
        """Path relative to the database root of a file ``name`` of this section."""
        return posixpath.normpath(posixpath.join(self.folder, name))

    def parse_name(self, name: str) -> tuple[int, int] | None:
        """Grid index named by a file ``name`` (relative to ``folder``), or None."""
        parts, named = [], set()
        for literal, field, _, _ in string.Formatter().parse(self.pattern):
            parts.append(re.escape(literal))
            if field is None:
                continue
            value = r" *\d+" if field != "ext" else "|".join(map(re.escape, self.extensions))
            group = f"?P<{field}>" if field not in named else "?:"  # repeats: checked below
            parts.append(f"({group}{value})")
            named.add(field)
        m = re.fullmatch("".join(parts), name)
        if m is None:
            return None
        i, j = int(m["x"]), int(m["y"])
        return (i, j) if name in self.file_names(i, j) else None

    def parse_path(self, relative: str) -> tuple[int, int] | None:
        """Grid index named by a path relative to the database root, or None."""
        name = relative if self.folder == "." else posixpath.relpath(relative, self.folder)
        return None if name.startswith("../") else self.parse_name(name)

    @abc.abstractmethod
    def geometry(self) -> CatadioptricGeometry | PanoramaGeometry:
        """The camera model of these images (in geometry.py's radians)."""

    @model_validator(mode="after")
    def _camera_model_valid(self) -> ImageSection:
        self.geometry()  # geometry.py raises ValueError for an impossible camera model
        return self


class RawImages(ImageSection):
    """Raw catadioptric images."""

    extensions: Annotated[tuple[str, ...], Field(strict=False, min_length=1)] = (
        "png",
        "pgm",
        "jpg",
    )
    catadioptric: CatadioptricSection  # the raw images' camera model

    def geometry(self) -> CatadioptricGeometry:
        return self.catadioptric.geometry(self.size)

    @model_validator(mode="after")
    def _centre_inside(self) -> RawImages:
        (u, v), (width, height) = self.catadioptric.centre, self.size
        if not (0 <= u <= width - 1 and 0 <= v <= height - 1):
            raise ValueError(
                f"catadioptric.centre [{u:g}, {v:g}] lies outside the {width} x {height} image "
                f"(pixel centres [0, {width - 1}] x [0, {height - 1}])"
            )
        return self


class UnfoldedImages(ImageSection):
    """Unfolded (cylindrical, equiangular) panoramas."""

    folder: str = "unfolded"
    panorama: PanoramaSection  # the panoramas' camera model

    def geometry(self) -> PanoramaGeometry:
        return self.panorama.geometry(self.size)

    @model_validator(mode="after")
    def _zero_column_inside(self) -> UnfoldedImages:
        zero, width = self.panorama.zero_column, self.size[0]
        if not 0 <= zero < width:
            raise ValueError(
                f"panorama.zero_column {zero:g} is not a column of the {width}-wide image: "
                f"it must lie in [0, {width})"
            )
        return self


class ImagesSection(StrictTypesModel):
    """The image kinds of a database: one or both of ``raw`` and ``unfolded``."""

    raw: RawImages | None = None  # raw catadioptric images (that need unwrapping)
    unfolded: UnfoldedImages | None = None  # unfolded panoramas

    @model_validator(mode="after")
    def _at_least_one(self) -> ImagesSection:
        if self.raw is None and self.unfolded is None:
            raise ValueError("images needs at least one of 'raw' and 'unfolded'")
        return self


class Generator(StrictTypesModel):
    """A generated set: the world spec (all fields) and the spec key its files were made with."""

    spec: WorldSpec  # the generated world's spec, every field
    # the spec's key (16 hex digits) the files were made with; checked against the spec
    key: Annotated[str, Field(pattern=r"^[0-9a-f]{16}$")] | None = None


class Manifest(StrictTypesModel):
    """One grid database: see the module docstring and ``data_manifests/*.yaml``."""

    schema_version: Literal[1] = Field(alias="schema")  # the manifest format's version
    name: Name  # letters, digits, . _ -
    description: str = ""  # one line on what the database is
    source: Source | None = None  # where a real set comes from (optional for your own sets)
    grid: GridSection  # the capture grid: labels, spacing, origin, order
    # required: the world heading every image faces (deg, ccw from the grid's +x axis)
    heading_deg: Annotated[float, Field(allow_inf_nan=False)]
    # per-position headings where they differ, by grid key "X_Y"
    headings_deg: dict[str, Annotated[float, Field(allow_inf_nan=False)]] = {}
    images: ImagesSection  # one or both kinds of image
    generator: Generator | None = None  # a generated set's world spec and its key
    ground_truth: str | None = None  # a generated set's ground-truth file, relative path

    model_config = ConfigDict(populate_by_name=True)  # "schema" or schema_version

    @model_validator(mode="before")
    @classmethod
    def _heading_given(cls, data: Any) -> Any:
        """No silent default for the heading: a wrong one turns every home direction."""
        if isinstance(data, dict) and "heading_deg" not in data:
            raise ValueError(
                "heading_deg is required: the world direction (deg, ccw from the grid's +x "
                "axis) every image faces; Vardy's Bielefeld sets and the guide's example "
                "use 90.0 (images facing +y), generated worlds 0.0"
            )
        return data

    @field_validator("ground_truth")
    @classmethod
    def _ground_truth_inside(cls, value: str | None) -> str | None:
        return None if value is None else _relative_posix(value, "ground_truth")

    @model_validator(mode="after")
    def _consistent(self) -> Manifest:
        grid = self.grid.label_grid()  # keys and file names are labels
        for key in self.headings_deg:
            try:
                i, j = parse_grid_key(key)
            except ValueError:
                raise ValueError(f"headings_deg: {key!r} is not a grid key 'X_Y'") from None
            if not grid.contains(i, j):
                raise ValueError(f"headings_deg: {key!r} is outside the {_shape(grid)} grid")
        for kind in self.kinds:
            section = self.section(kind)
            for key, names in (("files", section.files), ("fingerprints", section.fingerprints)):
                for name in names:
                    if not grid.contains(*section.parse_name(name)):
                        raise ValueError(f"images.{kind}.{key}: {name!r} is outside the grid")
        if self.generator is not None:
            self._check_generator(self.generator.spec)
        elif self.ground_truth is not None:
            raise ValueError("ground_truth is only for generated sets (with a generator)")
        return self

    def _check_generator(self, spec: WorldSpec) -> None:
        """A generated set's grid, heading and cameras must be those of its spec."""
        if not _same(self.grid.to_grid(), spec.to_grid()) or self.grid.order != "as-written":
            raise ValueError(f"grid does not match generator.spec (which gives {spec.to_grid()})")
        if not math.isclose(self.heading_deg, spec.heading_deg) or self.headings_deg:
            raise ValueError("heading_deg must be generator.spec.heading_deg, headings_deg empty")
        expected = {"raw": spec.raw.geometry(), "unfolded": spec.unfolded.geometry()}
        for kind in self.kinds:
            if not _same(self.section(kind).geometry(), expected[kind]):
                raise ValueError(f"images.{kind} does not match generator.spec.{kind}")

    # ------------------------------------------------------------------ queries

    @property
    def kind(self) -> Literal["real", "generated"]:
        """'generated' for a set with a generator, 'real' for captured (or user-made) sets."""
        return "generated" if self.generator is not None else "real"

    @property
    def kinds(self) -> tuple[ImageKind, ...]:
        """The image kinds present, in the order ("raw", "unfolded")."""
        return tuple(k for k in KINDS if getattr(self.images, k) is not None)

    def section(self, kind: str) -> RawImages | UnfoldedImages:
        """The image section of ``kind``; DataError if the database has none."""
        section = getattr(self.images, kind, None) if kind in KINDS else None
        if section is None:
            raise DataError(
                f"database {self.name!r} has no {kind!r} images (it has: {', '.join(self.kinds)})"
            )
        return section

    def geometry(self, kind: str) -> CatadioptricGeometry | PanoramaGeometry:
        return self.section(kind).geometry()

    def to_grid(self) -> Grid:
        return self.grid.to_grid()

    def heading(self, i: int, j: int) -> float:
        """World heading (radians, ccw from +x) of the image at grid position (i, j)."""
        a, b = self.grid.label(i, j)
        return math.radians(self.headings_deg.get(f"{a}_{b}", self.heading_deg))

    # ------------------------------------------------------------------ YAML

    def to_yaml(self) -> str:
        """The manifest as YAML, keys in schema order, short lists inline."""
        data = self.model_dump(mode="json", by_alias=True, exclude_none=True)
        for section in data["images"].values():
            section["files"] = section.pop("files")  # the long lists last, after the camera
            fingerprints = section.pop("fingerprints")
            if fingerprints:
                section["fingerprints"] = fingerprints
        if self.generator is not None:  # every keyed spec field, None included: the spec is exact
            data["generator"]["spec"] = self.generator.spec.canonical_data()
        return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)


def _shape(grid: Grid) -> str:
    return f"{grid.shape[0]} x {grid.shape[1]}"


def _same(a: Any, b: Any) -> bool:
    """Dataclasses equal field by field, floats within 1e-9 relative / absolute."""
    for x, y in zip(dataclasses.astuple(a), dataclasses.astuple(b), strict=True):
        if isinstance(x, str) or isinstance(y, str):
            if x != y:
                return False
        elif np.shape(x) != np.shape(y) or not np.allclose(x, y, rtol=1e-9, atol=1e-9):
            return False
    return True


class _Dumper(yaml.SafeDumper):
    """Lists of scalars inline ([10, 17]); mappings as blocks."""


def _represent_list(dumper: yaml.SafeDumper, data: list) -> yaml.Node:
    flow = all(not isinstance(v, dict | list) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_Dumper.add_representer(list, _represent_list)


# ---------------------------------------------------------------------- loading


def load_manifest(path: Path) -> Manifest:
    """Read and validate a manifest file; ConfigError names the file, line and key path.

    The file is read once a call; text parsed before in this process is not parsed again
    (manifests are frozen): runs and their workers look the same manifests up many times, and
    a lookup of a parsed text costs a hundredth of parsing it (synth-original's 60 KB: 0.28 ms
    to read and look up, 31 ms to parse)."""
    return _parsed(read_small_text(Path(path), MAX_YAML_BYTES, "manifest", ConfigError), str(path))


@functools.lru_cache(maxsize=64)
def _parsed(text: str, origin: str) -> Manifest:
    """The manifest in ``text`` (read from ``origin``), parsed once per text."""
    return parse_manifest(text, origin)


def parse_manifest(text: str, origin: str) -> Manifest:
    """Validate manifest YAML ``text``; ``origin`` (a file name) starts every error message."""
    return parse_model(Manifest, text, origin, what="manifest")
