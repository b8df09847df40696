"""How commands name a database, and open one: the same way in ``data verify``, ``data show``
and ``data check`` (and, through :func:`database_label`, wherever else a database is named).

A database is given by a known name (``synth-original``), a manifest file, a folder holding a
``manifest.yaml`` or a folder in the Brains on Board format (:mod:`homebench.data.bob`); it is
named by its name (a manifest's, or a BoB folder's), followed by what the user gave where that
was a path: ``lab-corridor (lab/corridor.yaml)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from homebench.data.bob import open_bob
from homebench.data.catalog import bob_folder, resolve
from homebench.data.database import GridDatabase
from homebench.data.posed import PosedDatabase


def database_label(name: str, locator: str | Path) -> str:
    """``name`` (a manifest's), with ``locator`` (what named the database) in parentheses
    where it is not that name: a manifest's path or a database folder."""
    given = str(locator)
    return name if given == name else f"{name} ({given})"


@dataclass(frozen=True)
class OpenedDatabase:
    """A database as a command opened it: its label, warnings on it and notes on what was
    assumed in reading it (each starting with the label), and the database: a grid database,
    or a database of posed images (``posed``: the Brains on Board format), grids among them."""

    label: str
    warnings: tuple[str, ...]
    notes: tuple[str, ...] = ()
    grid: GridDatabase | None = None
    posed: PosedDatabase | None = None

    @property
    def database(self) -> GridDatabase:
        """The grid database; DataError naming the database when it is a route (or other
        posed images: ``posed.database()`` reads them as places)."""
        if self.grid is not None:
            return self.grid
        assert self.posed is not None
        return self.posed.grid_database()  # raises: a route


def open_database(locator: str | Path, path: Path | None = None) -> OpenedDatabase:
    """The database ``locator`` names (images in ``path`` or their usual place; see
    :func:`homebench.data.catalog.resolve`), its label, warnings and notes."""
    folder = bob_folder(locator, path)
    if folder is not None:
        posed = open_bob(folder)
        label = database_label(posed.name, locator)
        grid = posed.grid_database() if posed.grid is not None else None
        warnings = tuple(f"{label}: {warning}" for warning in posed.warnings)
        notes = tuple(f"{label}: {note}" for note in posed.notes)
        return OpenedDatabase(label, warnings, notes, grid, posed)
    db = resolve(locator, path)
    label = database_label(db.name, locator)
    return OpenedDatabase(label, tuple(f"{label}: {w}" for w in db.unmatched_patterns()), grid=db)
