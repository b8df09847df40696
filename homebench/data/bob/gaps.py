"""Rows of ``database_entries.csv`` without a pose (X, Y or Heading empty or NaN): left out,
or filled as navbench fills them.

Recorded routes have such rows where the GPS gave no fix (BoB's ``dataset_recorder``,
``projects/dataset_recorder/dataset_recorder.cc``, writes NaN positions then) or the IMU no
attitude; a grid has them where a capture failed. ``missing_poses`` (:mod:`.overrides`) says
what to do with them:

- ``skip`` (the default): every such row is left out, its image unread; one note counts them
  (on a grid their positions become holes: :mod:`.grid`).
- ``interpolate``, as navbench does (BoB's Python ``Database(..., interpolate_xy=True)``,
  ``_interpolate_nan_entries`` in ``python/navigation/bob_robotics/navigation/__init__.py``):
  a route row's position is interpolated linearly between the nearest rows before and after
  it that have one, by ``Timestamp [ms]`` where every row has one and they increase
  (navbench's parameter), else by row. Rows before the first position or after the last are
  left out: there is nothing to interpolate between (navbench asserts that the first row has
  a position and copies the last one into the rows after it). A route row without a heading
  gets the direction of travel, of the step into it from the row before (out of it, for the
  first row), as BoB's recorded route headings are (:mod:`.conventions`); navbench recomputes
  every row's heading from the positions (``_get_headings_from_xy``: the step out of each
  row), homebench only the missing ones. They are written in the folder's heading convention
  (compass bearings unless ``headings`` says otherwise), so that they read as the others do; a
  row that does not move has no direction of travel and is left out. A grid row without X or
  Y takes the position of its Grid X, Grid Y (:mod:`.grid` places it); a grid row without a
  heading is left out: a grid recorder's heading is no direction of travel.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from homebench.data.bob.entries import HEADING, POSITION, TIMESTAMP, Entries
from homebench.data.bob.overrides import MissingPoses
from homebench.data.posed import listed
from homebench.errors import DataError
from homebench.geometry import HeadingConvention

BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Kept:
    """The rows of an entries file that have (or were given) a pose, in file order:
    ``entries`` (grid rows may keep NaN positions, which their grid fills), the ``skipped``
    rows' files and a ``note`` on what was done (None when every row had a pose)."""

    entries: Entries
    skipped: tuple[str, ...] = ()
    note: str | None = None


def keep_posed(
    entries: Entries,
    mode: MissingPoses,
    is_grid: bool,
    headings: HeadingConvention,
    overrides_name: str,
) -> Kept:
    """The rows of ``entries`` with a pose, those without one left out or filled by ``mode``
    (see the module docstring); ``headings``: how the file writes headings, those filled
    among them. DataError naming the file when no row is left."""
    placed = np.all(np.isfinite(entries.xyz_mm[:, :2]), axis=1)
    headed = np.isfinite(entries.heading_deg)
    if placed.all() and headed.all():
        return Kept(entries)
    filled, kept, how = entries, placed & headed, ""
    if mode == "interpolate" and is_grid:
        kept, how = headed, "placed at their Grid X, Grid Y"
    elif mode == "interpolate":
        filled, kept, by = _interpolated(entries, placed, headed, headings)
        how = (
            f"placed between their neighbours (positions linearly by {by}, headings along "
            "the direction of travel)"
        )
    lacking = np.flatnonzero(~(placed & headed))
    if not kept.any():
        raise DataError(
            f"{entries.path}: none of its {len(entries.files)} rows has both a position and a "
            f"heading (missing_poses: {mode})"
        )
    note = _note(entries, lacking, int(np.sum(~kept)), how, is_grid, overrides_name)
    skipped = tuple(entries.files[k] for k in np.flatnonzero(~kept))
    return Kept(filled.rows(np.flatnonzero(kept)), skipped, note)


def _interpolated(
    entries: Entries, placed: BoolArray, headed: BoolArray, headings: HeadingConvention
) -> tuple[Entries, BoolArray, str]:
    """A route's rows with positions interpolated between rows that have them and headings
    along the direction of travel, which rows are kept, and what the positions were
    interpolated by."""
    n = len(entries.files)
    t, by = _parameter(entries)
    xyz = entries.xyz_mm.copy()
    rows = np.arange(n)
    anchors = np.flatnonzero(placed)
    between = ~placed & (rows > anchors.min(initial=n)) & (rows < anchors.max(initial=-1))
    for axis in (0, 1):
        xyz[between, axis] = np.interp(t[between], t[placed], xyz[placed, axis])
    on_route = np.flatnonzero(placed | between)
    heading = entries.heading_deg.copy()
    travel = _travel_deg(xyz[on_route, :2])  # world, degrees ccw from +x; NaN: not moving
    recorded = np.mod(headings.from_world_deg(travel), 360.0)
    heading[on_route] = np.where(headed[on_route], heading[on_route], recorded)
    kept = (placed | between) & np.isfinite(heading)
    return replace(entries, xyz_mm=xyz, heading_deg=heading), kept, by


def _parameter(entries: Entries) -> tuple[NDArray[np.float64], str]:
    """What positions are interpolated by, (n,), and its name: the timestamps where every
    row has one and they increase, else the row numbers."""
    t = entries.time_ms
    if t is not None and np.all(np.isfinite(t)) and np.all(np.diff(t) > 0):
        return t, TIMESTAMP
    return np.arange(len(entries.files), dtype=np.float64), "row"


def _travel_deg(xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Direction of travel (degrees ccw from +x) at each of the route's points ``xy`` (m, 2):
    of the step into it, or where that is none (the first point, or no move) of the step out
    of it; NaN where neither moves. Shape (m,)."""
    none = np.full((1, 2), np.nan)
    into = np.vstack([none, np.diff(xy, axis=0)])
    out = np.vstack([np.diff(xy, axis=0), none])
    step = np.where((np.hypot(*into.T) > 0)[:, None], into, out)
    moves = np.hypot(*step.T) > 0
    return np.where(moves, np.degrees(np.arctan2(step[:, 1], step[:, 0])), np.nan)


def _note(
    entries: Entries,
    lacking: NDArray[np.int64],
    left_out: int,
    how: str,
    is_grid: bool,
    overrides_name: str,
) -> str:
    """The note on the rows without a pose (``lacking``, of which ``left_out`` were left
    out; the others placed ``how``)."""
    lines = listed([str(entries.lines[k]) for k in lacking])
    said = (
        f"{len(lacking)} of the {len(entries.files)} rows have no {POSITION[0]}, {POSITION[1]} "
        f"or {HEADING} (empty or nan; line(s) {lines})"
    )
    if not how:
        fills = (
            "places a grid row that has a heading at its Grid X, Grid Y"
            if is_grid
            else "places a route's rows between their neighbours"
        )
        return (
            f"{entries.path}: {said}: left out, their images unread (missing_poses: skip; "
            f"missing_poses: interpolate in {overrides_name} {fills})"
        )
    placed = len(lacking) - left_out
    why = "no heading" if is_grid else "before the first position, after the last or not moving"
    out = f", {left_out} left out ({why}: nothing to fill them from)" if left_out else ""
    return f"{entries.path}: {said}: {placed} {how}{out} (missing_poses: interpolate)"
