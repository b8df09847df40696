"""Check a database folder against its manifest, and record a folder's sums into a manifest.

:func:`verify` raises the first kind of problem it finds (missing images, sha256 mismatches,
unreadable or wrongly sized images, unreadable ground truth) and otherwise returns a report of
what it checked, what it could not check (no known sum) and warnings (unrelated files).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from homebench.data.database import GridDatabase
from homebench.data.generate import MANIFEST_NAME, is_generated
from homebench.data.manifest import Manifest, load_manifest
from homebench.errors import ChecksumMismatchError, DataError
from homebench.fileio import sha256_file, write_text_atomic


@dataclass(frozen=True)
class VerifyReport:
    """Outcome of a verification that found no error. Paths are relative to ``root``."""

    name: str
    root: Path
    checked: tuple[str, ...]
    unchecked: tuple[str, ...]
    warnings: tuple[str, ...]

    @property
    def n_images(self) -> int:
        return len(self.checked) + len(self.unchecked)


def layout_files(db: GridDatabase) -> dict[str, dict[str, Path]]:
    """kind -> file name (relative to its section folder) -> path, for every grid image.

    Raises MissingImagesError naming the positions without a file.
    """
    db.check_layout()
    files: dict[str, dict[str, Path]] = {}
    for kind in db.kinds:
        folder = db.root / db.manifest.section(kind).folder
        paths = (db.path(i, j, kind) for i, j in db.grid.indices())
        files[kind] = {p.relative_to(folder).as_posix(): p for p in paths}
    return files


def verify(
    database_or_folder: GridDatabase | Path | str, manifest: Manifest | Path | None = None
) -> VerifyReport:
    """Verify a database (or a folder, against ``manifest`` or its own ``manifest.yaml``).

    Raises MissingImagesError, ChecksumMismatchError (every mismatching file, expected and
    found), CorruptImageError, ImageSizeError or DataError (ground truth).
    """
    db = _database(database_or_folder, manifest)
    files = layout_files(db)
    checked, unchecked, warnings, mismatches = [], [], [], []
    for kind, names in files.items():
        section = db.manifest.section(kind)
        for name, path in names.items():
            expected = section.files.get(name)
            relative = path.relative_to(db.root).as_posix()
            if expected is None:
                unchecked.append(relative)
                continue
            found = sha256_file(path)
            if found != expected:
                mismatches.append((path, expected, found))
            checked.append(relative)
        for name in sorted(set(section.files) - set(names)):
            warnings.append(f"{section.relative_path(name)}: listed in the manifest, not used")
    if mismatches:
        raise ChecksumMismatchError(mismatches)
    for kind in db.kinds:
        for i, j in db.grid.indices():
            db.image(i, j, kind)  # decodes and checks the size
    if db.manifest.ground_truth is not None:
        db.ground_truth()
    generator = db.manifest.generator
    if generator is not None and generator.key not in (None, generator.spec.key()):
        warnings.append(
            f"the sums were recorded for spec key {generator.key}; this homebench's renderer "
            f"gives key {generator.spec.key()}: regenerate and record the sums again"
        )
    known = {p.relative_to(db.root).as_posix() for names in files.values() for p in names.values()}
    known |= {MANIFEST_NAME, db.manifest.ground_truth}
    warnings += [_extra_file_warning(db, rel) for rel in _all_files(db.root) if rel not in known]
    return VerifyReport(db.name, db.root, tuple(checked), tuple(unchecked), tuple(warnings))


def _database(
    database_or_folder: GridDatabase | Path | str, manifest: Manifest | Path | None
) -> GridDatabase:
    """The database to verify: given, or a folder with a manifest (given or its own)."""
    if isinstance(manifest, str | Path):
        manifest = load_manifest(Path(manifest))
    if isinstance(database_or_folder, GridDatabase):
        db = database_or_folder
        return db if manifest is None else GridDatabase(manifest, db.root)
    folder = Path(database_or_folder)
    if not folder.is_dir():
        raise DataError(f"{folder}: no such database folder")
    return GridDatabase(manifest or load_manifest(folder / MANIFEST_NAME), folder)


def _all_files(root: Path) -> list[str]:
    """Every file under ``root``, as sorted paths relative to it."""
    found = []
    for folder, _, names in os.walk(root):
        base = Path(folder).relative_to(root)
        found += [(base / n).as_posix() for n in names]
    return sorted(found)


def _extra_file_warning(db: GridDatabase, relative: str) -> str:
    for kind in db.kinds:
        position = db.manifest.section(kind).parse_path(relative)
        if position is not None:
            return f"{relative}: {kind} image of grid position {position}, outside the grid"
    return f"{relative}: unrelated file"


def record_sums(manifest_path: Path, root: Path) -> Manifest:
    """Rewrite ``manifest_path``'s ``files`` sections with the sha256 of the images in ``root``.

    For a generated set ``root`` must hold a finished generation of the manifest's spec; the
    manifest's ``generator.key`` is set to the spec's current key. Comments in the file are
    not kept. Returns the new manifest.
    """
    manifest_path, root = Path(manifest_path), Path(root)
    manifest = load_manifest(manifest_path)
    if manifest.generator is not None and not is_generated(root, manifest.generator.spec):
        raise DataError(f"{root}: not a finished generation of {manifest_path}'s spec")
    files = layout_files(GridDatabase(manifest, root))
    data = manifest.model_dump(by_alias=True)
    for kind, names in files.items():
        data["images"][kind]["files"] = {n: sha256_file(p) for n, p in sorted(names.items())}
    if manifest.generator is not None:
        data["generator"]["key"] = manifest.generator.spec.key()
    updated = Manifest.model_validate(data)
    write_text_atomic(manifest_path, updated.to_yaml())
    return updated
