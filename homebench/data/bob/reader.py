"""Open a Brains on Board image database: a folder read as a database of posed images.

Positions become metres (mm / 1000; Z is not used). Headings are read as BoB writes them,
compass bearings (0 along +y, growing clockwise: :mod:`.conventions`), and become homebench's
(degrees ccw from +x, in [0, 360): 90 - h); ``headings`` in ``homebench.yaml`` states another
convention. Each image keeps its own. Rows without a position or heading are left out or
filled (``missing_poses``: :mod:`.gaps`). A grid database (``type: grid`` in the metadata, or
Grid columns and no metadata) maps Grid X, Grid Y onto homebench's grid index (i, j) (:mod:`.grid`):
each label once, one Grid Z layer, the positions on a regular grid, ``grid.order`` saying
which position each label was taken at, shifted to start at 0, positions without an image
holes. A route database keeps its poses in file order. No file it reads may lie outside the
folder through a symbolic link (a link inside it, or a folder that is one, is fine).
"""

from __future__ import annotations

import functools
import os
import re
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from homebench.data.bob.camera import camera_model
from homebench.data.bob.conventions import ANT_WORLD_CAMERA, BOB_HEADINGS
from homebench.data.bob.entries import HEADING as HEADING_COLUMN
from homebench.data.bob.entries import Entries, read_entries
from homebench.data.bob.gaps import keep_posed
from homebench.data.bob.grid import GridReading, read_grid
from homebench.data.bob.layout import DESCRIPTION_FILES, ENTRIES_NAME, METADATA_NAME, OVERRIDES_NAME
from homebench.data.bob.metadata import Metadata, read_metadata
from homebench.data.bob.overrides import BobOverrides, HeadingsOverride, read_overrides
from homebench.data.grid_order import GridOrder
from homebench.data.posed import PosedDatabase
from homebench.errors import DataError
from homebench.fileio import check_image

Stamp = tuple[int, int, int] | None


def open_bob(folder: Path, overrides: BobOverrides | None = None) -> PosedDatabase:
    """The database in ``folder`` (its ``homebench.yaml``, then ``overrides``, replacing what
    the metadata says). A folder read before in this process, whose description files are
    unchanged since, is not parsed again. DataError or ConfigError naming the file (and line)
    of the first problem."""
    folder = Path(os.path.abspath(Path(folder).expanduser()))
    stamps = tuple(_stamp(folder / name) for name in DESCRIPTION_FILES)
    return _open(folder, stamps, overrides)


def _stamp(path: Path) -> Stamp:
    """(inode, size, modification time) of ``path``; None where it cannot be read."""
    try:
        stat = path.stat()
    except OSError:
        return None
    return stat.st_ino, stat.st_size, stat.st_mtime_ns


@functools.lru_cache(maxsize=16)
def _open(folder: Path, stamps: tuple[Stamp, ...], overrides: BobOverrides | None) -> PosedDatabase:
    """The database in ``folder`` as of its description files' ``stamps``."""
    inside = _Inside(folder)
    inside.check(DESCRIPTION_FILES, lambda k: str(folder / DESCRIPTION_FILES[k]))
    entries = read_entries(folder / ENTRIES_NAME)
    inside.check(entries.files, entries.where)
    metadata = read_metadata(folder / METADATA_NAME)
    own = read_overrides(folder / OVERRIDES_NAME)
    merged = overrides.over(own) if overrides is not None else own or BobOverrides()
    if metadata is not None and metadata.video_file:
        raise DataError(
            f"{folder / METADATA_NAME}: a video database (videoFile: {metadata.video_file}): "
            "homebench reads image files; write the frames as images (BoB's "
            "ImageDatabase::unwrap does)"
        )
    is_grid = _is_grid(metadata, entries, folder)
    overrides_name = str(folder / OVERRIDES_NAME)
    headings = (merged.headings or HeadingsOverride()).over(BOB_HEADINGS)
    kept = keep_posed(entries, merged.missing_poses or "skip", is_grid, headings, overrides_name)
    entries = kept.entries
    size = (metadata.resolution if metadata else None) or _size(folder / entries.files[0])
    camera = camera_model(metadata, merged, size, str(folder / METADATA_NAME), overrides_name)
    xy = entries.xyz_mm[:, :2] / 1000.0
    notes = list(camera.notes)
    if merged.headings is None or None in (merged.headings.zero_deg, merged.headings.direction):
        notes.append(_headings_note(overrides_name))
    notes += [kept.note] if kept.note else []
    reading: GridReading | None = None
    in_doubt = False
    order: GridOrder = "as-written"
    if is_grid:
        order = merged.grid.order if merged.grid is not None else "as-written"
        info = metadata.grid if metadata is not None else None
        reading = read_grid(entries, xy, order, info, str(folder / METADATA_NAME))
        xy = reading.xy
        notes += reading.notes
        in_doubt = merged.grid is None and metadata is not None and _is_ant_world(metadata)
        if in_doubt:
            notes.append(_order_note(overrides_name))
    return PosedDatabase(
        name=merged.name or _name(folder),
        description=merged.description
        or f"Brains on Board {'grid' if is_grid else 'route'} database ({ENTRIES_NAME})",
        root=folder,
        kind=camera.kind,
        size=size,
        camera=camera.geometry,
        xy=_read_only(xy),
        heading_deg=_read_only(np.mod(headings.to_world_deg(entries.heading_deg), 360.0)),
        files=entries.files,
        listing=ENTRIES_NAME,
        own_files=tuple(name for name in DESCRIPTION_FILES if (folder / name).exists()),
        grid=reading.grid if reading else None,
        grid_index=_read_only(reading.index) if reading else None,
        grid_order=order,
        order_in_doubt=in_doubt,
        labels=reading.labels if reading else None,
        headings=headings,
        skipped_files=kept.skipped,
        notes=tuple(notes),
        warnings=reading.warnings if reading else (),
    )


def _headings_note(overrides_name: str) -> str:
    """The note saying how headings were read, where homebench.yaml does not say."""
    return (
        f"{HEADING_COLUMN} read as BoB writes it: compass bearings, 0 along +y, growing "
        f"clockwise (headings: {{zero_deg: {BOB_HEADINGS.zero_deg:g}, direction: "
        f"{BOB_HEADINGS.direction}}}); {overrides_name} sets them"
    )


def _is_ant_world(metadata: Metadata) -> bool:
    return metadata.camera is not None and metadata.camera.name == ANT_WORLD_CAMERA


def _order_note(overrides_name: str) -> str:
    """The note on the labels of a grid from BoB's Ant World tools."""
    return (
        "grid labels read as written (grid: {order: as-written}); BoB's grid recorder, which "
        "ant_world_db_creator uses, labels the images it renders in another order than it "
        "visits the positions (GridRecorder::getPositions and ::record): transposed on a "
        "square grid (grid.order: bob-recorder); `homebench data check` says which order the "
        f"images show, {overrides_name} sets it"
    )


class _Inside:
    """Checks that files named relative to ``folder`` stay inside it, links followed."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.real = os.path.realpath(folder)
        self.inner = os.path.join(self.real, "")  # what every path inside starts with
        self.parents: dict[str, str | None] = {}  # a file's folder -> its real path if outside

    def check(self, names: Sequence[str], where: Callable[[int], str]) -> None:
        """DataError starting with ``where(k)`` for the first of ``names`` (the k-th) that
        lies outside the folder."""
        for k, name in enumerate(names):
            real = self._outside(name)
            if real is not None:
                raise DataError(
                    f"{where(k)}: {name} leads through a symbolic link to {real}, outside the "
                    f"database folder {self.real}"
                )

    def _outside(self, name: str) -> str | None:
        """Where ``name`` leads, links followed, if that lies outside the folder; else None.
        A file that is no link lies where its folder does (each folder resolved once)."""
        path = os.path.join(self.folder, name)
        if os.path.islink(path):
            return self._beyond(os.path.realpath(path))
        parent, base = os.path.split(path)
        if parent not in self.parents:
            self.parents[parent] = self._beyond(os.path.realpath(parent))
        outside = self.parents[parent]
        return None if outside is None else os.path.join(outside, base)

    def _beyond(self, real: str) -> str | None:
        """``real`` (a resolved path) if it lies outside the folder, else None."""
        return None if real == self.real or real.startswith(self.inner) else real


def _is_grid(metadata: Metadata | None, entries: Entries, folder: Path) -> bool:
    """Whether the database is a grid: its metadata's ``type``, else its Grid columns."""
    if metadata is None or metadata.type is None:
        return entries.grid is not None
    if metadata.type == "grid" and entries.grid is None:
        raise DataError(
            f"{folder / METADATA_NAME}: type: grid, but {entries.path} has no Grid X, Grid Y, "
            "Grid Z columns"
        )
    return metadata.type == "grid"


def _size(first: Path) -> tuple[int, int]:
    """The size of the first image, where the metadata gives no resolution."""
    header = check_image(first)
    return header.width, header.height


def _read_only(array: NDArray) -> NDArray:
    array.setflags(write=False)
    return array


def _name(folder: Path) -> str:
    """A database name (letters, digits, . _ -) made of the folder's name."""
    name = re.sub(r"[^A-Za-z0-9._-]+", "-", folder.name).lstrip("._-")
    return name or "bob-database"
