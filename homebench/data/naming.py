"""How commands name a database, and open one: the same way in ``data verify``, ``data show``
and ``data check`` (and, through :func:`database_label`, wherever else a database is named).

A database is given by a known name (``synth-original``), a manifest file or a folder
holding a ``manifest.yaml``; it is named by its manifest's ``name``, followed by what the user
gave where that was a path: ``lab-corridor (lab/corridor.yaml)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from homebench.data.catalog import resolve
from homebench.data.database import GridDatabase


def database_label(name: str, locator: str | Path) -> str:
    """``name`` (a manifest's), with ``locator`` (what named the database) in parentheses
    where it is not that name: a manifest's path or a database folder."""
    given = str(locator)
    return name if given == name else f"{name} ({given})"


@dataclass(frozen=True)
class OpenedDatabase:
    """A database as a command opened it: the database, its label and warnings on its
    manifest (each starting with the label)."""

    database: GridDatabase
    label: str
    warnings: tuple[str, ...]


def open_database(locator: str | Path, path: Path | None = None) -> OpenedDatabase:
    """The database ``locator`` names (images in ``path`` or their usual place; see
    :func:`homebench.data.catalog.resolve`), its label and its manifest's warnings."""
    db = resolve(locator, path)
    label = database_label(db.name, locator)
    return OpenedDatabase(db, label, tuple(f"{label}: {w}" for w in db.unmatched_patterns()))
