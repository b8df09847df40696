"""Databases of posed images: every image with the pose it was taken at.

A recorded route, or a grid recorded as a list of images with their poses (metres and degrees
in homebench's world frame: x right, y up, headings counter-clockwise from +x), in recording
order; one image kind per database. A database whose images carry grid indices is also a
:class:`~homebench.data.database.GridDatabase` (:meth:`PosedDatabase.grid_database`), with the
per-image headings as the manifest's ``headings_deg``: what the engine and the grid commands
read; positions of its grid without an image are holes
(:class:`~homebench.geometry.HoledGrid`). Any other (a route, any posed images) is read by the
engine as posed places, image k at index (k, 0) (:meth:`PosedDatabase.database`,
:class:`~homebench.geometry.Places`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from homebench.data.database import GridDatabase
from homebench.data.grid_order import GridOrder
from homebench.data.manifest import (
    SCHEMA_VERSION,
    CatadioptricSection,
    GridSection,
    ImagesSection,
    Manifest,
    PanoramaSection,
    RawImages,
    UnfoldedImages,
)
from homebench.data.progress import over
from homebench.errors import DataError
from homebench.fileio import check_image, file_problem, read_grey
from homebench.geometry import (
    CatadioptricGeometry,
    Grid,
    HeadingConvention,
    PanoramaGeometry,
    Places,
    Pose,
    grid_key,
    missing_positions,
)
from homebench.views import ImageKind, View

#: Files named in a list before "and N more".
SHOWN = 3


@dataclass(frozen=True, eq=False)
class PosedDatabase:
    """Images at poses: ``xy`` (n, 2) metres and ``heading_deg`` (n,) degrees per image,
    ``files`` (relative to ``root``) of one ``kind`` and ``size`` [width, height] with the
    camera model ``camera``. A grid's images have ``grid_index`` (n, 2) on ``grid``, their
    positions, which ``grid_order`` mapped their labels to; ``order_in_doubt``: the labels may
    well not be the positions (see :class:`ListedGridDatabase`). ``headings``: how the
    recording wrote its headings (``heading_deg`` are homebench's, turned from them). Without
    a grid the poses are a route, in recording order. ``labels``: the labels of a grid's
    images and the grid they span (:class:`GridLabels`). ``listing`` is the file that lists
    the images, ``own_files`` the files (relative to ``root``) that describe the database,
    not images, ``skipped_files`` those it lists but were left out (rows without a pose);
    ``notes`` say what was assumed in reading it, ``warnings`` where its files disagree."""

    name: str
    description: str
    root: Path
    kind: ImageKind
    size: tuple[int, int]
    camera: PanoramaGeometry | CatadioptricGeometry
    xy: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    files: tuple[str, ...]
    listing: str
    own_files: tuple[str, ...] = ()
    grid: Grid | None = None
    grid_index: NDArray[np.int64] | None = None
    grid_order: GridOrder = "as-written"
    order_in_doubt: bool = False
    labels: GridLabels | None = None
    headings: HeadingConvention = HeadingConvention()
    skipped_files: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.files)

    @property
    def kinds(self) -> tuple[ImageKind, ...]:
        return (self.kind,)

    @property
    def recorded_heading_deg(self) -> NDArray[np.float64]:
        """The headings as the recording wrote them (its convention, ``headings``), (n,)."""
        return self.headings.from_world_deg(self.heading_deg)

    def pose(self, k: int) -> Pose:
        """The pose of image ``k``: position in metres, heading in radians."""
        return Pose(float(self.xy[k, 0]), float(self.xy[k, 1]), math.radians(self.heading_deg[k]))

    def path(self, k: int) -> Path:
        return self.root / self.files[k]

    def image(self, k: int) -> NDArray[np.uint8]:
        """Grey image ``k``, shape (height, width) uint8; errors name the file."""
        return read_grey(self.path(k), self.size)

    def view(self, k: int) -> View:
        return View(self.image(k), self.camera)

    def check_images(self) -> None:
        """Check every image without decoding it: present, in a known format, of ``size``, not
        visibly cut short (see :func:`homebench.fileio.check_image`); errors name the files."""
        paths = [self.path(k) for k in range(len(self))]
        missing = [name for name, path in zip(self.files, paths, strict=True) if not path.is_file()]
        for name in missing:  # there, but no file (a folder, a FIFO, a symbolic link loop)
            problem = file_problem(self.root / name, "image")
            if problem:
                raise DataError(f"{self.root / name}: {problem}")
        if missing:
            raise DataError(
                f"{self.root}: {len(missing)} image(s) listed in {self.listing} are missing: "
                + listed(missing)
            )
        for path in over(paths, len(paths), f"check {self.name}"):
            check_image(path, self.size)

    def layout(self) -> str:
        """What the poses are, as words: "a 10 x 17 grid 0.3 m apart", "a route of ..."."""
        if self.grid is not None:
            nx, ny = self.grid.shape
            missing = missing_positions(self.grid)
            holes = f", {len(missing)} of its positions without an image" if missing else ""
            return f"a {nx} x {ny} grid {self.grid.spacing:g} m apart{holes}"
        length = float(np.sum(np.hypot(*np.diff(self.xy, axis=0).T)))
        return f"a route of {len(self)} poses, {length:.2f} m long"

    def grid_database(self) -> ListedGridDatabase:
        """The images as a grid database; DataError when they have no grid (runs, the data
        commands and closed-loop runs read any posed images: :meth:`database`)."""
        if self.grid is None or self.grid_index is None:
            raise DataError(
                f"{self.root}: {self.layout()}, not a grid; this needs a grid database (rows "
                f"with Grid X, Grid Y, Grid Z in its {self.listing})"
            )
        return self._listed(self.grid, self.grid_index)

    def database(self) -> ListedGridDatabase:
        """The images as the engine reads them: on their grid, or else as posed places, image
        k at index (k, 0) of :class:`~homebench.geometry.Places` (a route, or any poses)."""
        if self.grid is not None and self.grid_index is not None:
            return self._listed(self.grid, self.grid_index)
        places = Places.of(self.xy)
        index = np.stack([np.arange(len(self)), np.zeros(len(self), dtype=np.int64)], axis=1)
        return self._listed(places, index)

    def _listed(self, grid: Grid, grid_index: NDArray[np.int64]) -> ListedGridDatabase:
        """The images on ``grid`` (a grid, or places), image k at ``grid_index[k]`` (n, 2)."""
        values, counts = np.unique(self.heading_deg, return_counts=True)
        heading = float(values[np.argmax(counts)])
        keys = [grid_key(int(i), int(j)) for i, j in grid_index]
        manifest = Manifest(
            schema=SCHEMA_VERSION,
            name=self.name,
            description=self.description,
            grid=GridSection(shape=grid.shape, spacing=grid.spacing, origin=grid.origin),
            heading_deg=heading,
            headings_deg={
                k: float(h) for k, h in zip(keys, self.heading_deg, strict=True) if h != heading
            },
            images=ImagesSection(**{self.kind: self._section()}),
        )
        files = {
            (int(i), int(j)): name for (i, j), name in zip(grid_index, self.files, strict=True)
        }
        on_grid = self.grid is grid
        return ListedGridDatabase(
            manifest,
            self.root,
            files,
            self.notes,
            grid,
            self.grid_order if on_grid else "as-written",
            self.order_in_doubt,
            self.labels if on_grid else None,
            self.warnings,
        )

    def _section(self) -> RawImages | UnfoldedImages:
        """The manifest section of the images (files listed, not named by its pattern)."""
        if isinstance(self.camera, CatadioptricGeometry):
            catadioptric = CatadioptricSection.from_geometry(self.camera)
            return RawImages(folder=".", size=self.size, catadioptric=catadioptric)
        panorama = PanoramaSection.from_geometry(self.camera)
        return UnfoldedImages(folder=".", size=self.size, panorama=panorama)


@dataclass(frozen=True, eq=False)
class GridLabels:
    """The labels of a grid's images as its listing gives them (Grid X, Grid Y): ``of`` maps
    each position (i, j) to its image's label, ``grid`` is the grid the labels span, of the
    recorder's size, with the position of label (0, 0) as its origin (see
    :attr:`~homebench.data.database.GridDatabase.label_grid`)."""

    of: Mapping[tuple[int, int], tuple[int, int]]
    grid: Grid


def listed(names: list[str]) -> str:
    """The first :data:`SHOWN` of ``names``, "and N more" for the rest."""
    more = f" and {len(names) - SHOWN} more" if len(names) > SHOWN else ""
    return ", ".join(names[:SHOWN]) + more


class ListedGridDatabase(GridDatabase):
    """A grid database whose image files are listed per position (``files``: relative to
    ``root``), not named by its manifest's pattern; its headings are the listing's, ``notes``
    say what was assumed in reading it. ``grid``, when given, replaces the manifest's: the
    :class:`~homebench.geometry.Places` of posed images (of the manifest's shape (n, 1)).
    ``order``: how the listing's labels were mapped to the positions (``grid.order``, already
    applied to ``files``); ``order_in_doubt``: nobody stated it and the labels may well not be
    the positions (a grid of BoB's Ant World tools), so that where the images fit a mirrored
    direction as well as another order, ``data check`` proposes the order. ``labels``: the
    images' labels as listed (a block cut from a larger grid's are not its positions' indices;
    None: ``order`` undone); ``warnings``: where the database's files disagree."""

    def __init__(
        self,
        manifest: Manifest,
        root: Path,
        files: Mapping[tuple[int, int], str],
        notes: tuple[str, ...] = (),
        grid: Grid | None = None,
        order: GridOrder = "as-written",
        order_in_doubt: bool = False,
        labels: GridLabels | None = None,
        warnings: tuple[str, ...] = (),
    ):
        super().__init__(manifest, root)
        self.files = dict(files)
        self.notes = notes
        self.order = order
        self.order_in_doubt = order_in_doubt
        self.labels = labels
        self.warnings = warnings
        if grid is not None:  # posed places, or a grid with holes: what the manifest lacks
            self.grid = grid

    @property
    def grid_order(self) -> GridOrder:
        return self.order

    @property
    def shared_heading_deg(self) -> float | None:
        return None

    def label(self, i: int, j: int) -> tuple[int, int]:
        if self.labels is None:
            return super().label(i, j)
        self._check_position(i, j)
        return self.labels.of[(i, j)]

    @property
    def label_grid(self) -> Grid:
        return super().label_grid if self.labels is None else self.labels.grid

    def candidate_paths(self, i: int, j: int, kind: str) -> list[Path]:
        self.manifest.section(kind)  # DataError for a kind the database has not
        return [self.root / self.files[(i, j)]]

    def unmatched_patterns(self) -> list[str]:
        """No pattern to mistype (check_layout names what is missing): the notes on what was
        assumed take the place of its lines, so that a run says them where it would."""
        return list(self.notes)
