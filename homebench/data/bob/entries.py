"""``database_entries.csv``: one row per image, read as input from anyone.

The header names the columns; spaces around the commas do not count. ``X [mm], Y [mm], Z [mm],
Heading [degrees], Filename`` are required; grid databases add ``Grid X, Grid Y, Grid Z`` (all
three, as BoB requires); other columns (``Pitch [degrees]``, ``Roll [degrees]``, a sensor's)
are ignored, but for ``Timestamp [ms]`` (BoB's recorders write it, navbench interpolates
positions by it), read where it is a number. An empty value is NaN, as pandas writes it and
BoB reads it (``ImageDatabase::loadCSV``, ``src/navigation/image_database.cc``: "Treat empty
strings as NaNs"), and so is ``nan``: BoB's ``dataset_recorder`` writes NaN positions where
the GPS gave none. X, Y and Heading may be NaN (:mod:`.gaps` leaves such rows out or fills
them), never infinite; Z may be empty (homebench does not use it). A ``Frame`` column without
``Filename`` is a video database, which homebench does not read.

Bounds: at most :data:`MAX_ENTRIES_BYTES` and :data:`MAX_ENTRIES` rows; a grid index has at most
7 digits; a file name follows the manifest's rule (no empty, '.' or '..' component, no leading
'/', no backslash or control character), so that it cannot leave the database folder. Every
problem is one DataError naming the file and line.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from homebench.data.manifest import MAX_GRID_POSITIONS, outside_problem
from homebench.errors import DataError
from homebench.fileio import read_small_text

#: Most rows (images) of a database, as many as a manifest's grid may have positions.
MAX_ENTRIES = MAX_GRID_POSITIONS
#: Largest entries file: a million rows of 250 bytes (positions, a name, sensor columns).
MAX_ENTRIES_BYTES = 256 << 20

POSITION = ("X [mm]", "Y [mm]", "Z [mm]")
HEADING = "Heading [degrees]"
FILENAME = "Filename"
TIMESTAMP = "Timestamp [ms]"
GRID = ("Grid X", "Grid Y", "Grid Z")
REQUIRED = (*POSITION, HEADING, FILENAME)
_INDEX = re.compile(r"[0-9]{1,7}")


@dataclass(frozen=True)
class Entries:
    """The rows of an entries file in file order: ``xyz_mm`` (n, 3) millimetres and
    ``heading_deg`` (n,) degrees (NaN where the row has none), ``files`` relative to the
    database folder, ``grid`` (n, 3) grid indices or None, ``lines`` the line of each row in
    ``path``, ``time_ms`` (n,) its ``Timestamp [ms]`` (NaN where it is no number) or None."""

    path: Path
    xyz_mm: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    files: tuple[str, ...]
    grid: NDArray[np.int64] | None
    lines: tuple[int, ...]
    time_ms: NDArray[np.float64] | None = None

    def where(self, k: int) -> str:
        """``file:line`` of row ``k``."""
        return f"{self.path}:{self.lines[k]}"

    def rows(self, kept: NDArray[np.int64]) -> Entries:
        """The rows ``kept`` (indices, in order) of these."""
        return Entries(
            path=self.path,
            xyz_mm=self.xyz_mm[kept],
            heading_deg=self.heading_deg[kept],
            files=tuple(self.files[k] for k in kept),
            grid=None if self.grid is None else self.grid[kept],
            lines=tuple(self.lines[k] for k in kept),
            time_ms=None if self.time_ms is None else self.time_ms[kept],
        )


def read_entries(path: Path) -> Entries:
    """The entries of ``path``; DataError naming the file and line of the first problem."""
    text = read_small_text(path, MAX_ENTRIES_BYTES, "entries file")
    reader = csv.reader(io.StringIO(text, newline=""), skipinitialspace=True, strict=True)
    try:
        header = next(reader, None)
        if header is None:
            raise DataError(f"{path}: the entries file is empty (no header line)")
        columns = _columns(path, [name.strip() for name in header])
        rows: list[tuple[int, list[str]]] = []
        for row in reader:
            if not any(cell.strip() for cell in row):
                continue  # a blank line
            if len(row) != len(header):
                raise DataError(
                    f"{path}:{reader.line_num}: {len(row)} values, but the header names "
                    f"{len(header)} columns"
                )
            if len(rows) == MAX_ENTRIES:
                raise DataError(f"{path}: more than {MAX_ENTRIES:,} images")
            rows.append((reader.line_num, [cell.strip() for cell in row]))
    except csv.Error as error:
        raise DataError(f"{path}:{reader.line_num}: not CSV ({error})") from None
    if not rows:
        raise DataError(f"{path}: no images listed (only the header line)")
    return _entries(path, columns, rows)


def _columns(path: Path, names: list[str]) -> dict[str, int]:
    """Column index by name; DataError when a required one is missing or a name repeats."""
    columns: dict[str, int] = {}
    for k, name in enumerate(names):
        if name in columns:
            raise DataError(f"{path}:1: the column {name!r} is named twice")
        columns[name] = k
    if FILENAME not in columns and "Frame" in columns:
        raise DataError(
            f"{path}:1: a video database (a Frame column, no Filename): homebench reads image "
            "files; write the frames as images (BoB's ImageDatabase::unwrap does)"
        )
    for name in REQUIRED:
        if name not in columns:
            raise DataError(
                f"{path}:1: no {name!r} column (the header names: {', '.join(names)}); "
                f"required: {', '.join(REQUIRED)}"
            )
    given = [name for name in GRID if name in columns]
    if given and len(given) < len(GRID):
        missing = ", ".join(name for name in GRID if name not in columns)
        raise DataError(f"{path}:1: {given[0]!r} but no {missing}: a grid gives all three")
    return columns


def _entries(path: Path, columns: dict[str, int], rows: list[tuple[int, list[str]]]) -> Entries:
    """The parsed ``rows`` (line, cells)."""
    xyz, heading, files, grid, time = [], [], [], [], []
    has_grid = GRID[0] in columns
    for line, cells in rows:
        where = f"{path}:{line}"
        x, y, z = (_number(cells[columns[name]], name, where) for name in POSITION)
        h = _number(cells[columns[HEADING]], HEADING, where)
        for name, value in ((POSITION[0], x), (POSITION[1], y), (HEADING, h)):
            if math.isinf(value):
                raise DataError(
                    f"{where}: {name} is {cells[columns[name]]}: a position or heading is a "
                    "finite number, or empty or nan where there is none"
                )
        xyz.append((x, y, z))
        heading.append(h)
        files.append(_file_name(cells[columns[FILENAME]], where))
        if has_grid:
            grid.append([_index(cells[columns[name]], name, where) for name in GRID])
        if TIMESTAMP in columns:
            time.append(_time(cells[columns[TIMESTAMP]]))
    return Entries(
        path=path,
        xyz_mm=np.array(xyz, dtype=np.float64),
        heading_deg=np.array(heading, dtype=np.float64),
        files=tuple(files),
        grid=np.array(grid, dtype=np.int64) if has_grid else None,
        lines=tuple(line for line, _ in rows),
        time_ms=np.array(time, dtype=np.float64) if TIMESTAMP in columns else None,
    )


def _number(cell: str, column: str, where: str) -> float:
    """The number in ``cell`` (empty: NaN); DataError otherwise."""
    if not cell:
        return math.nan
    try:
        return float(cell)
    except ValueError:
        raise DataError(f"{where}: {column} {cell!r} is not a number") from None


def _time(cell: str) -> float:
    """The timestamp in ``cell``; NaN where it is none (an extra column: not an error)."""
    try:
        return float(cell)
    except ValueError:
        return math.nan


def _index(cell: str, column: str, where: str) -> int:
    """The grid index in ``cell``: a whole number from 0 with at most 7 digits."""
    if _INDEX.fullmatch(cell) is None:
        raise DataError(f"{where}: {column} {cell!r} is not a grid index (0, 1, 2, ...)")
    return int(cell)


def _file_name(name: str, where: str) -> str:
    """``name`` if it names a file inside the database folder; DataError otherwise."""
    problem = outside_problem(name)
    if problem is not None:
        raise DataError(
            f"{where}: Filename {name!r} {problem}: it could lie outside the database folder"
        )
    return name
