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
7 digits; a heading at most :data:`MAX_HEADING_DEG` degrees either way; a file name follows the
manifest's rule (no empty, '.' or '..' component, no leading '/', no backslash or control
character), so that it cannot leave the database folder. Every problem is one DataError
naming the file and line.
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
from homebench.data.progress import over
from homebench.errors import DataError
from homebench.fileio import read_small_text

#: Most rows (images) of a database, as many as a manifest's grid may have positions.
MAX_ENTRIES = MAX_GRID_POSITIONS
#: Largest entries file: a million rows of 250 bytes (positions, a name, sensor columns).
MAX_ENTRIES_BYTES = 256 << 20
#: Largest heading (degrees, either way): a recorder that counts turns does not turn 2,778
#: times; beyond, the degrees are no angle (at 1e17 a double cannot tell 360 from 0).
MAX_HEADING_DEG = 1e6

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
        for row in over(reader, None, f"read {path.name}", "row"):
            cells = [cell.strip() for cell in row]
            if not any(cells):
                continue  # a blank line
            if len(row) != len(header):
                raise DataError(
                    f"{path}:{reader.line_num}: {len(row)} values, but the header names "
                    f"{len(header)} columns"
                )
            if len(rows) == MAX_ENTRIES:
                raise DataError(f"{path}: more than {MAX_ENTRIES:,} images")
            rows.append((reader.line_num, cells))
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
    """The parsed ``rows`` (line, cells), column by column."""
    lines = tuple(line for line, _ in rows)
    table = list(zip(*(cells for _, cells in rows), strict=True))  # the cells of each column
    cells = {name: table[k] for name, k in columns.items()}
    xyz = np.column_stack([_numbers(cells[name], name, path, lines) for name in POSITION])
    heading = _numbers(cells[HEADING], HEADING, path, lines)
    for name, values in ((POSITION[0], xyz[:, 0]), (POSITION[1], xyz[:, 1]), (HEADING, heading)):
        _refuse(path, lines, cells[name], name, np.isinf(values), INFINITE)
    _refuse(path, lines, cells[HEADING], HEADING, np.abs(heading) > MAX_HEADING_DEG, FAR)
    for k, name in enumerate(cells[FILENAME]):
        _file_name(name, f"{path}:{lines[k]}")
    grid = None
    if GRID[0] in columns:
        grid = np.array([_indices(cells[name], name, path, lines) for name in GRID]).T
    time = None
    if TIMESTAMP in columns:
        time = np.array([_time(cell) for cell in cells[TIMESTAMP]], dtype=np.float64)
    return Entries(path, xyz, heading, cells[FILENAME], grid, lines, time)


#: Why a position or heading that :func:`_refuse` refuses cannot be one.
INFINITE = "a position or heading is a finite number, or empty or nan where there is none"
FAR = f"a heading is at most {MAX_HEADING_DEG:,.0f} degrees either way (2,778 turns)"


def _refuse(
    path: Path, lines: tuple[int, ...], cells: tuple[str, ...], column: str,
    wrong: NDArray[np.bool_], why: str,
) -> None:  # fmt: skip
    """DataError naming the line of the first of ``cells`` (of ``column``) that is ``wrong``:
    "file:7: Heading [degrees] is inf: ``why``"."""
    first = np.flatnonzero(wrong)
    if first.size:
        k = int(first[0])
        raise DataError(f"{path}:{lines[k]}: {column} is {cells[k]}: {why}")


def _numbers(
    cells: tuple[str, ...], column: str, path: Path, lines: tuple[int, ...]
) -> NDArray[np.float64]:
    """The numbers in ``cells`` (empty: NaN), shape (n,); DataError naming the line of the
    first that is none."""
    try:
        return np.array([float(cell) if cell else math.nan for cell in cells], dtype=np.float64)
    except ValueError:
        for k, cell in enumerate(cells):
            _number(cell, column, f"{path}:{lines[k]}")
        raise


def _number(cell: str, column: str, where: str) -> float:
    """The number in ``cell`` (empty: NaN); DataError otherwise."""
    if not cell:
        return math.nan
    try:
        return float(cell)
    except ValueError:
        raise DataError(f"{where}: {column} {cell!r} is not a number") from None


def _indices(cells: tuple[str, ...], column: str, path: Path, lines: tuple[int, ...]) -> list[int]:
    """The grid indices in ``cells``; DataError naming the line of the first that is none."""
    return [_index(cell, column, f"{path}:{lines[k]}") for k, cell in enumerate(cells)]


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
