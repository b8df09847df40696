"""The known databases and where their files are.

Known databases are the manifests in the repository's ``data_manifests/`` plus those in the
folders listed in ``$HOMEBENCH_MANIFESTS`` (``os.pathsep``-separated; they come first, so a user
manifest may replace a shipped one of the same name). Anything else can be named by the path of a
manifest file, or of a folder holding a ``manifest.yaml``, or of a folder in the Brains on Board
format (a ``database_entries.csv`` and no ``manifest.yaml``: :mod:`homebench.data.bob`), whose
grid databases open as grid databases.

Where the images are: for a real set, ``path`` if given, else the folder in the manifest's
``source.path_env`` variable, else (for a manifest given by path) the manifest's own folder. For a
generated set, its cache folder ``<data dir>/synth/<name>-<spec key>/``, filled only by
:func:`ensure_generated`.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import homebench
from homebench.data.bob import ENTRIES_NAME, BobOverrides, is_bob_folder, open_bob
from homebench.data.database import GridDatabase
from homebench.data.generate import (
    MANIFEST_NAME,
    Progress,
    generate,
    generated_root,
    is_generated,
)
from homebench.data.manifest import Manifest, load_manifest
from homebench.data.synth.spec import VARIANTS, WorldSpec
from homebench.errors import ConfigError, DataError, UnknownDatabaseError
from homebench.fileio import open_regular
from homebench.suggest import unknown
from homebench.yamlio import MAX_YAML_BYTES

#: The manifests shipped with the repository (the package is installed editable from it).
SHIPPED_MANIFESTS = Path(homebench.__file__).resolve().parent.parent / "data_manifests"


@dataclass(frozen=True)
class CatalogEntry:
    """A known manifest: its database name, file and content."""

    name: str
    path: Path
    manifest: Manifest


@dataclass(frozen=True)
class DatabaseRow:
    """One line of :func:`list_databases`."""

    name: str
    kind: Literal["real", "generated"]
    location: str
    present: bool
    description: str


def manifest_dirs() -> list[Path]:
    """Folders searched for manifests: ``$HOMEBENCH_MANIFESTS`` first, then the shipped ones."""
    extra = os.environ.get("HOMEBENCH_MANIFESTS", "")
    dirs = [Path(d).expanduser() for d in extra.split(os.pathsep) if d]
    return [*dirs, SHIPPED_MANIFESTS]


def _manifest_files() -> Iterator[Path]:
    """The manifest files of :func:`manifest_dirs`, in the order in which they win."""
    for folder in manifest_dirs():
        if folder.is_dir():
            yield from sorted([*folder.glob("*.yaml"), *folder.glob("*.yml")])


def known_manifests() -> dict[str, CatalogEntry]:
    """Every manifest in :func:`manifest_dirs`, by database name (the first folder wins)."""
    entries: dict[str, CatalogEntry] = {}
    for path in _manifest_files():
        manifest = load_manifest(path)
        entries.setdefault(manifest.name, CatalogEntry(manifest.name, path, manifest))
    return entries


def known_manifest(name: str) -> CatalogEntry | None:
    """``known_manifests().get(name)``, parsing only the files that may declare ``name``.

    A manifest file lists every image's sums, so parsing all the known ones costs about 1.5 s,
    in the main process and again in every job worker that opens a database by name. A file
    whose one top-level ``name:`` line (:func:`_declared_name`) names another database is
    skipped unparsed; any other file is parsed, in the order :func:`known_manifests` takes.
    """
    for path in _manifest_files():
        declared = _declared_name(path)
        if declared is not None and declared != name:
            continue
        manifest = load_manifest(path)
        if manifest.name == name:
            return CatalogEntry(name, path, manifest)
    return None


#: A top-level ``name:`` line with a plain scalar (as homebench writes manifests).
_NAME_LINE = re.compile(rb"^name:[ \t]*([A-Za-z0-9][A-Za-z0-9_.+-]*)[ \t]*\r?$", re.MULTILINE)


def _declared_name(path: Path) -> str | None:
    """The database name a manifest file declares on its one top-level ``name:`` line, read
    without parsing the file; None when it has no such line, or several (a flow collection
    continued at the margin could hold one): the file must then be parsed. Reads at most the
    manifest size limit, and only from a regular file."""
    try:
        with open_regular(path) as f:
            text = f.read(MAX_YAML_BYTES + 1)
    except OSError:
        return None
    found = _NAME_LINE.findall(text)
    return found[0].decode("ascii") if len(found) == 1 else None


def find_manifest(
    name_or_path: str | Path, overrides: BobOverrides | None = None
) -> tuple[Manifest, Path | None]:
    """The manifest of a database name, manifest file or database folder (of a Brains on Board
    database: the manifest it maps onto, with ``overrides``; posed places as an (n, 1) grid).

    Returns the manifest and, when it was given by path, the folder it lives in.
    """
    folder = bob_folder(name_or_path, overrides=overrides)
    if folder is not None:
        return open_bob(folder, overrides).database().manifest, folder
    candidate = Path(name_or_path).expanduser()
    if (candidate / MANIFEST_NAME).is_file():
        return load_manifest(candidate / MANIFEST_NAME), candidate
    if candidate.is_file() or candidate.suffix in (".yaml", ".yml"):
        return load_manifest(candidate), candidate.parent
    entry = known_manifest(str(name_or_path))
    if entry is not None:
        return entry.manifest, None
    if candidate.is_dir():
        raise DataError(
            f"{candidate}: a database folder needs a {MANIFEST_NAME} (or, in the Brains on "
            f"Board format, a {ENTRIES_NAME})"
        )
    raise UnknownDatabaseError(
        unknown(
            "database",
            str(name_or_path),
            known_manifests(),
            " (or give the path of a manifest .yaml or of a database folder)",
        )
    )


def bob_folder(
    name_or_path: str | Path, path: Path | None = None, overrides: BobOverrides | None = None
) -> Path | None:
    """The folder of the Brains on Board database ``name_or_path`` names (a folder with a
    ``database_entries.csv`` and no ``manifest.yaml``, which would win); None for any other
    locator. ConfigError for a ``path`` (images elsewhere) given with such a folder, and for
    ``overrides`` of any other database."""
    candidate = Path(name_or_path).expanduser()
    if not is_bob_folder(candidate) or (candidate / MANIFEST_NAME).is_file():
        if overrides is not None:
            raise ConfigError(
                f"{candidate}: overrides of the camera model are for Brains on Board database "
                "folders (with a database_entries.csv); a manifest states its own"
            )
        return None
    if path is not None:
        raise ConfigError(
            f"{candidate}: a Brains on Board database is read from its own folder; the path "
            f"{path} is for databases named by a manifest"
        )
    return candidate


def resolve(
    name_or_path: str | Path, path: Path | None = None, overrides: BobOverrides | None = None
) -> GridDatabase:
    """The database named by ``name_or_path``, with images in ``path`` or its usual place; a
    Brains on Board database with ``overrides`` (its own folder holds its images), on its grid
    or, without one, as posed places (:meth:`~homebench.data.posed.PosedDatabase.database`)."""
    folder = bob_folder(name_or_path, path, overrides)
    if folder is not None:
        return open_bob(folder, overrides).database()
    manifest, own_folder = find_manifest(name_or_path)
    if manifest.generator is not None:
        root = generated_location(manifest, own_folder, path)
        if not is_generated(root, manifest.generator.spec):
            raise DataError(
                f"database {manifest.name!r} is not generated in {root}; "
                f"run `homebench data generate {name_or_path}`"
            )
        return GridDatabase(load_manifest(root / MANIFEST_NAME), root)
    root = _real_location(manifest, own_folder, path)
    if not root.is_dir():
        raise DataError(f"{root}: the folder of database {manifest.name!r} does not exist")
    return GridDatabase(manifest, root)


def ensure_generated(
    name_or_path: str | Path,
    out_dir: Path | None = None,
    jobs: int = 1,
    progress: Progress | None = None,
) -> GridDatabase:
    """Generate a generated set unless its folder is already complete; return the database."""
    manifest, own_folder = find_manifest(name_or_path)
    spec = _generator_spec(manifest)
    root = generated_location(manifest, own_folder, out_dir)
    return _generate_into(spec, manifest.name, manifest.description, root, jobs, progress)


def generate_variant(
    name_or_path: str | Path,
    variant: str,
    out_dir: Path | None = None,
    jobs: int = 1,
    progress: Progress | None = None,
) -> GridDatabase:
    """Generate ``variant`` of a generated set's world: same seed, room, grid and cameras.

    Its name swaps the set's variant suffix ("synth-original" -> "synth-day"), or appends
    "-<variant>"; it goes to ``out_dir`` or that name's cache folder.
    """
    manifest, _ = find_manifest(name_or_path)
    spec = _generator_spec(manifest)
    if variant not in VARIANTS:
        raise ConfigError(unknown("variant", variant, VARIANTS))
    spec = WorldSpec.model_validate({**spec.model_dump(), "variant": variant})
    stem = manifest.name.removesuffix(f"-{manifest.generator.spec.variant}")
    name = f"{stem}-{variant}"
    root = Path(out_dir) if out_dir is not None else generated_root(name, spec)
    return _generate_into(spec, name, "", root, jobs, progress)


def _generator_spec(manifest: Manifest) -> WorldSpec:
    if manifest.generator is None:
        raise DataError(f"database {manifest.name!r} is a real set: there is nothing to generate")
    return manifest.generator.spec


def _generate_into(
    spec: WorldSpec,
    name: str,
    description: str,
    root: Path,
    jobs: int,
    progress: Progress | None,
) -> GridDatabase:
    generate(spec, root, jobs, name, description=description, progress=progress)
    return GridDatabase(load_manifest(root / MANIFEST_NAME), root)


def generated_location(manifest: Manifest, own_folder: Path | None, path: Path | None) -> Path:
    """``path``, else the folder the manifest came from if it is the generation, else the cache."""
    spec = manifest.generator.spec
    if path is not None:
        return Path(path).expanduser()
    if own_folder is not None and is_generated(own_folder, spec):
        return own_folder
    return generated_root(manifest.name, spec)


def _real_location(manifest: Manifest, own_folder: Path | None, path: Path | None) -> Path:
    """``path``, else ``$path_env``, else the manifest's own folder; else DataError (says how)."""
    if path is not None:
        return Path(path).expanduser()
    env = manifest.source.path_env if manifest.source else None
    if env and os.environ.get(env):
        return Path(os.environ[env]).expanduser()
    if own_folder is not None:
        return own_folder
    how = f"set {env}=/path/to/copy or " if env else ""
    raise DataError(
        f"database {manifest.name!r} is a real set that homebench cannot download; "
        f"{how}pass --path /path/to/copy"
        + (f" (source: {manifest.source.url})" if manifest.source and manifest.source.url else "")
    )


def _is_present(manifest: Manifest, root: Path) -> bool:
    """Whether every file of the database is in ``root`` (a generated set: finished there)."""
    if manifest.generator is not None:
        return is_generated(root, manifest.generator.spec)
    try:
        GridDatabase(manifest, root).check_layout()
    except DataError:  # images missing, or a folder that cannot be opened
        return False
    return True


def list_databases() -> list[DatabaseRow]:
    """One row per known database: name, kind, where its files are (or would go), present."""
    rows = []
    for entry in known_manifests().values():
        m = entry.manifest
        try:
            if m.generator is not None:
                root = generated_location(m, None, None)
            else:
                root = _real_location(m, None, None)
        except DataError:
            env = m.source.path_env if m.source else None
            location, present = (f"${env} not set" if env else "give --path"), False
        else:
            location, present = str(root), _is_present(m, root)
        rows.append(DatabaseRow(m.name, m.kind, location, present, m.description))
    return sorted(rows, key=lambda r: (r.kind, r.name))
