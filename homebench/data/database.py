"""A grid database on disk: a manifest plus the folder its file paths are relative to.

Images are read on demand, one file per call, and checked against the manifest's size (from the
file's header, before decoding); every error names the file or the grid positions it is about.
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from homebench.data.grid_order import GridOrder, label_of, label_shape
from homebench.data.manifest import Manifest
from homebench.errors import DataError, MissingImagesError
from homebench.fileio import check_image, file_problem, read_grey
from homebench.geometry import (
    CatadioptricGeometry,
    Grid,
    PanoramaGeometry,
    Pose,
    is_places,
    missing_positions,
)
from homebench.views import ImageKind, View


class GridDatabase:
    """Images addressed by grid index (i, j), in one or both kinds ("raw", "unfolded")."""

    def __init__(self, manifest: Manifest, root: Path):
        self.manifest = manifest
        self.root = Path(root)
        self.grid: Grid = manifest.to_grid()

    def __repr__(self) -> str:
        return f"GridDatabase({self.name!r}, root={str(self.root)!r})"

    @property
    def name(self) -> str:
        return self.manifest.name

    @property
    def kinds(self) -> tuple[ImageKind, ...]:
        return self.manifest.kinds

    def geometry(self, kind: str) -> CatadioptricGeometry | PanoramaGeometry:
        """Camera model of the images of ``kind``; DataError if the database has none."""
        return self.manifest.geometry(kind)

    def _check_position(self, i: int, j: int) -> None:
        if not self.grid.contains(i, j):
            nx, ny = self.grid.shape
            if is_places(self.grid):
                raise DataError(
                    f"place ({i},{j}) is outside database {self.name!r}, which holds {nx} posed "
                    f"images, not a grid: image k is place (k, 0), k in 0..{nx - 1}"
                )
            if (i, j) in missing_positions(self.grid):
                raise DataError(
                    f"grid position ({i},{j}) of database {self.name!r} has no image (one of "
                    f"the {len(missing_positions(self.grid))} positions its grid misses)"
                )
            raise DataError(
                f"grid position ({i},{j}) is outside database {self.name!r}, whose grid is "
                f"{nx} x {ny} (i in 0..{nx - 1}, j in 0..{ny - 1})"
            )

    def heading(self, i: int, j: int) -> float:
        """World heading (radians, ccw from +x) of the images at (i, j)."""
        self._check_position(i, j)
        return self.manifest.heading(i, j)

    def pose(self, i: int, j: int) -> Pose:
        """Camera pose at (i, j): grid position in metres and the image heading."""
        return self.grid.pose(i, j, self.heading(i, j))

    @property
    def shared_heading_deg(self) -> float | None:
        """The manifest's one heading (deg) when every position has it, so that correcting it
        turns every image; None when positions have their own."""
        return None if self.manifest.headings_deg else self.manifest.heading_deg

    @property
    def grid_order(self) -> GridOrder:
        """How the images' labels map to their positions (``grid.order``)."""
        return self.manifest.grid.order

    #: Whether the labels may well not be the positions (see ListedGridDatabase).
    order_in_doubt = False
    #: Where the database's own files disagree (a Brains on Board folder's metadata and
    #: entries), one line each.
    warnings: tuple[str, ...] = ()

    def label(self, i: int, j: int) -> tuple[int, int]:
        """The label of the image at grid position (i, j) (``grid.order`` undone)."""
        return label_of(self.grid_order, (i, j), self.grid.shape)

    @property
    def label_grid(self) -> Grid:
        """The grid of the labels: of the shape they span and the positions' spacing, its
        origin where the image labelled (0, 0) would be in any order, so that
        ``label_grid.position(*position_of(order, label, ...))`` places an image in ``order``."""
        shape = label_shape(self.grid_order, self.grid.shape)
        return Grid(shape, self.grid.spacing, self.grid.origin)

    def candidate_paths(self, i: int, j: int, kind: str) -> list[Path]:
        """The files that may hold the image of (i, j), in order: the pattern's name of its
        label (``grid.order``) with each extension."""
        section = self.manifest.section(kind)
        names = section.file_names(*self.manifest.grid.label(i, j))
        return [self.root / section.relative_path(n) for n in names]

    def path(self, i: int, j: int, kind: str) -> Path:
        """The file of (i, j): the first candidate that exists, else the first one."""
        self._check_position(i, j)
        paths = self.candidate_paths(i, j, kind)
        return next((p for p in paths if p.is_file()), paths[0])

    def image(self, i: int, j: int, kind: str) -> NDArray[np.uint8]:
        """Grey image at (i, j), shape (height, width) uint8, read from disk now.

        Raises MissingImagesError, CorruptImageError or ImageSizeError naming the file.
        """
        path = self.path(i, j, kind)
        if not path.is_file():
            self._check_unopenable(kind, [(i, j)])
            raise MissingImagesError(path.parent, [(i, j)])
        return read_grey(path, self.manifest.section(kind).size)

    def view(self, i: int, j: int, kind: str) -> View:
        """The image at (i, j) with its camera model."""
        return View(self.image(i, j, kind), self.geometry(kind))

    def missing(self, kind: str) -> list[tuple[int, int]]:
        """Grid positions with no file of ``kind``, in grid order."""
        return [(i, j) for i, j in self.grid.indices() if not self.path(i, j, kind).is_file()]

    def unmatched_patterns(self) -> list[str]:
        """One line per image kind whose pattern names no file at any grid position of an
        existing folder (a mistyped pattern), with the file names it looked for first."""
        lines = []
        for kind in self.kinds:
            section = self.manifest.section(kind)
            folder = self.root / section.folder
            if not folder.is_dir() or len(self.missing(kind)) < self.grid.size:
                continue
            names = section.file_names(0, 0)
            stem = os.path.commonprefix(names).rpartition(".")[0]  # "img_00_00" of .png, .pgm
            looked = "|".join([names[0], *(n.removeprefix(f"{stem}.") for n in names[1:])])
            lines.append(
                f"images.{kind}.pattern {section.pattern!r} matches no file: looked for "
                f"{looked} in {os.path.abspath(folder)}"
            )
        return lines

    def check_layout(self, kinds: tuple[str, ...] | None = None) -> None:
        """Raise MissingImagesError (naming the positions) if any image of ``kinds`` is absent,
        DataError if their folder cannot be opened (a symbolic link loop, a file)."""
        for kind in kinds or self.kinds:
            missing = self.missing(kind)
            if missing:
                folder = self.root / self.manifest.section(kind).folder
                self._check_folder(folder, kind)
                self._check_unopenable(kind, missing)
                raise MissingImagesError(Path(os.path.abspath(folder)), missing)

    def _check_folder(self, folder: Path, kind: str) -> None:
        """DataError if ``folder`` exists but is no folder that can be opened."""
        what = f"the {kind} image folder of database {self.name!r}"
        try:
            mode = os.stat(folder).st_mode
        except FileNotFoundError:
            return  # no folder: every image is missing
        except OSError as error:
            raise DataError(f"{folder}: cannot open {what} ({error.strerror or error})") from None
        if not stat.S_ISDIR(mode):
            raise DataError(f"{folder}: {what} is not a folder")

    def _check_unopenable(self, kind: str, positions: list[tuple[int, int]]) -> None:
        """DataError naming the first file of an image at ``positions`` that is there but
        is no file that can be opened (a symbolic link loop, a folder, a FIFO: see
        :func:`~homebench.fileio.file_problem`): such an image is not missing."""
        for i, j in positions:
            for path in self.candidate_paths(i, j, kind):
                problem = file_problem(path, "image")
                if problem:
                    raise DataError(f"{path}: {problem}")

    def check_images(self, kinds: tuple[str, ...]) -> None:
        """Check every image of ``kinds`` without decoding it: present, in a known format, of the
        manifest's size, not visibly cut short (see fileio.check_image). Raises
        MissingImagesError, CorruptImageError or ImageSizeError naming the file."""
        self.check_layout(kinds)
        for kind in kinds:
            size = self.manifest.section(kind).size
            for i, j in self.grid.indices():
                check_image(self.path(i, j, kind), size)

    def ground_truth(self) -> dict[str, Any]:
        """The ground truth of a generated set (camera poses and the world's objects)."""
        if self.manifest.ground_truth is None:
            raise DataError(f"database {self.name!r} has no ground truth (it is not generated)")
        path = self.root / self.manifest.ground_truth
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except OSError as error:
            raise DataError(f"{path}: cannot read the ground truth ({error.strerror})") from None
        except ValueError as error:
            raise DataError(f"{path}: the ground truth is not valid JSON ({error})") from None
