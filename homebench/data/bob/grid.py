"""A Brains on Board grid database's labels (Grid X, Grid Y) as homebench's grid.

- ``grid.order`` maps each label to the position its image was taken at
  (:mod:`homebench.data.grid_order`) on the recorder's whole grid: the metadata's
  ``grid.size`` (:mod:`.metadata`) where every label lies inside it, as a block cut from BoB's
  101 x 101 Ant World grid keeps the whole grid's labels and size; else the labels' span from
  0. Labels first, then positions: BoB's recorder order depends on the whole grid's size.
- The positions are shifted to start at 0, so that grid index (0, 0) is the block's first
  position; a note says by how much.
- Positions of the span without an image (a failed capture, a row left out by
  :mod:`.gaps`, a block whose labels the order scatters) are holes of a
  :class:`~homebench.geometry.HoledGrid`; a note counts them and names a few.
- The positions lie on a regular grid (:func:`~homebench.data.grid_fit.fit_grid`, of the
  labels that have an X and Y); a row without them (``missing_poses: interpolate``) is placed
  at its grid point.
- Metadata that disagrees with the entries (labels beyond ``grid.size``, a ``separationMM``
  or ``beginAtMM`` the positions do not fit) is a warning: the entries are read.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from homebench.data.bob.entries import Entries
from homebench.data.bob.metadata import GridInfo
from homebench.data.grid_fit import DECIMALS, MIN_TOLERANCE_M, TOLERANCE, fit_grid
from homebench.data.grid_order import GridOrder, Index, position_of, position_shape
from homebench.data.manifest import MAX_GRID_POSITIONS
from homebench.data.posed import GridLabels, listed
from homebench.errors import DataError
from homebench.geometry import Grid, holed_grid


@dataclass(frozen=True)
class GridReading:
    """A grid database's ``grid``, each image's ``index`` (i, j) on it, shape (n, 2), and
    position, ``xy`` (n, 2) metres (as written, or where ``grid.order`` puts its label), the
    images' ``labels``, ``notes`` on what was assumed and ``warnings`` where the metadata
    disagrees with the entries."""

    grid: Grid
    index: NDArray[np.int64]
    xy: NDArray[np.float64]
    labels: GridLabels
    notes: tuple[str, ...]
    warnings: tuple[str, ...]


def read_grid(
    entries: Entries,
    xy: NDArray[np.float64],
    order: GridOrder,
    info: GridInfo | None,
    metadata_name: str,
) -> GridReading:
    """The grid of ``entries`` (grid rows, positions ``xy`` (n, 2) metres, NaN where a row
    has none), its labels read in ``order`` on the recorder's grid ``info`` (the metadata's,
    in ``metadata_name``; None: none). DataError naming the file (and line) when the labels
    repeat, span more than one layer or too large a grid, or the positions lie on no grid."""
    assert entries.grid is not None
    _one_layer(entries)
    labels = entries.grid[:, :2]
    _no_repeats(entries, labels)
    warnings = []
    whole, problem = _whole(labels, info, metadata_name, entries)
    warnings += [problem] if problem else []
    positions = position_shape(order, whole)
    taken = np.array([position_of(order, (a, b), positions) for a, b in labels.tolist()])
    shift = taken.min(axis=0)
    index = (taken - shift).astype(np.int64)
    shape = (int(index[:, 0].max()) + 1, int(index[:, 1].max()) + 1)
    if shape[0] * shape[1] > MAX_GRID_POSITIONS:
        read = "" if order == "as-written" else f" (read in grid.order {order})"
        raise DataError(
            f"{entries.path}: Grid X, Grid Y span a {shape[0]} x {shape[1]} grid{read}; at "
            f"most {MAX_GRID_POSITIONS:,} positions are allowed"
        )
    rows = np.flatnonzero(np.all(np.isfinite(xy), axis=1))
    fitted = fit_grid(xy[rows], labels[rows], str(entries.path), lambda k: entries.where(rows[k]))
    warnings += _spacing_warnings(info, fitted, labels, metadata_name, entries)
    origin = np.asarray(fitted.origin) + shift * fitted.spacing
    present = np.zeros(shape, dtype=bool)
    present[index[:, 0], index[:, 1]] = True
    missing = [(int(i), int(j)) for i, j in np.argwhere(~present)]
    origin_xy = (round(float(origin[0]), DECIMALS), round(float(origin[1]), DECIMALS))
    grid = holed_grid(shape, fitted.spacing, origin_xy, missing)
    placed = grid.position(index[:, 0], index[:, 1])
    if order == "as-written":  # the positions as written; a row without them at its grid point
        placed = np.where(np.isfinite(xy), xy, placed)
    of = {(int(i), int(j)): (int(a), int(b)) for (i, j), (a, b) in zip(index, labels, strict=True)}
    notes = [_shift_note(entries, order, whole, shift, of)] if shift.any() else []
    notes += [_holes_note(entries, shape, missing)] if missing else []
    return GridReading(
        grid=grid,
        index=index,
        xy=placed,
        labels=GridLabels(of, Grid(whole, fitted.spacing, fitted.origin)),
        notes=tuple(notes),
        warnings=tuple(warnings),
    )


def _one_layer(entries: Entries) -> None:
    assert entries.grid is not None
    layers = np.unique(entries.grid[:, 2])
    if layers.size > 1:
        values = listed([str(z) for z in layers])
        raise DataError(
            f"{entries.path}: Grid Z takes {layers.size} values ({values}): homebench reads "
            "grids of one layer"
        )


def _no_repeats(entries: Entries, labels: NDArray[np.int64]) -> None:
    first: dict[tuple[int, int], int] = {}
    for k, (a, b) in enumerate(labels.tolist()):
        if (a, b) in first:
            raise DataError(
                f"{entries.where(k)}: grid position ({a}, {b}) again (first on line "
                f"{entries.lines[first[(a, b)]]})"
            )
        first[(a, b)] = k


def _whole(
    labels: NDArray[np.int64], info: GridInfo | None, metadata_name: str, entries: Entries
) -> tuple[Index, str | None]:
    """The recorder's grid size (nx, ny) in labels: the metadata's where every label lies
    inside it, else the labels' span from 0; and the warning where the metadata's does not
    hold them."""
    span = (int(labels[:, 0].max()) + 1, int(labels[:, 1].max()) + 1)
    if info is None or info.size is None:
        return span, None
    size = (info.size[0], info.size[1])
    if span[0] <= size[0] and span[1] <= size[1]:
        return size, None
    return span, (
        f"{metadata_name}: grid.size {list(info.size)} holds labels up to ({size[0] - 1}, "
        f"{size[1] - 1}), but Grid X, Grid Y in {entries.path} run up to ({span[0] - 1}, "
        f"{span[1] - 1}): the grid they span from 0, {span[0]} x {span[1]}, is read"
    )


def _spacing_warnings(
    info: GridInfo | None,
    fitted: Grid,
    labels: NDArray[np.int64],
    metadata_name: str,
    entries: Entries,
) -> list[str]:
    """Warnings where the metadata's ``separationMM`` (along the axes the labels vary) or
    ``beginAtMM`` (the position of label (0, 0)) disagree with the grid the positions fit."""
    if info is None:
        return []
    tolerance = max(TOLERANCE * fitted.spacing, MIN_TOLERANCE_M)
    warnings = []
    if info.separation_mm is not None:
        steps = [info.separation_mm[k] / 1000.0 for k in (0, 1) if np.ptp(labels[:, k]) > 0]
        if any(abs(step - fitted.spacing) > tolerance for step in steps):
            warnings.append(
                f"{metadata_name}: grid.separationMM {list(info.separation_mm)}, but the "
                f"positions in {entries.path} are {fitted.spacing * 1000:g} mm apart: the "
                "positions are read"
            )
    if info.begin_mm is not None:
        begin = np.array(info.begin_mm[:2]) / 1000.0
        if np.hypot(*(begin - fitted.origin)) > tolerance:
            x, y = (round(v * 1000.0, 1) for v in fitted.origin)
            warnings.append(
                f"{metadata_name}: grid.beginAtMM {list(info.begin_mm)}, but the positions in "
                f"{entries.path} put Grid X, Grid Y (0, 0) at ({x:g}, {y:g}) mm: the positions "
                "are read"
            )
    return warnings


def _shift_note(
    entries: Entries,
    order: GridOrder,
    whole: Index,
    shift: NDArray[np.int64],
    of: dict[tuple[int, int], tuple[int, int]],
) -> str:
    """The note on positions that do not start at 0, shifted by ``shift`` (i, j)."""
    sx, sy = (int(v) for v in shift)
    read = (
        "Grid X, Grid Y"
        if order == "as-written"
        else f"the positions grid.order {order} gives Grid X, Grid Y on the {whole[0]} x "
        f"{whole[1]} grid they were recorded on"
    )
    first = (
        f"goal [0, 0] is the image labelled {of[(0, 0)]}"
        if (0, 0) in of
        else "grid index [0, 0] has no image"
    )
    return (
        f"{entries.path}: {read} start at ({sx}, {sy}), not (0, 0): shifted to start there, "
        f"grid index [i, j] is position (i + {sx}, j + {sy}); {first}"
    )


def _holes_note(entries: Entries, shape: Index, missing: list[tuple[int, int]]) -> str:
    """The note on the positions of the grid without an image."""
    total = shape[0] * shape[1]
    have = "has" if len(missing) == 1 else "have"
    return (
        f"{entries.path}: {len(missing)} of the {total} positions of the {shape[0]} x "
        f"{shape[1]} grid {have} no image (grid index "
        f"{listed([f'[{i}, {j}]' for i, j in missing])}): runs and the data commands read the "
        f"{total - len(missing)} present; RR starts at them and steers by the nearest one "
        "present, catchment fails on stepping onto a missing one"
    )
