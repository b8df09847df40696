"""Check a database folder against its manifest, and record a folder's sums into a manifest;
check a database of posed images (the Brains on Board format) against its listing.

:func:`verify` raises the first kind of problem it finds (missing images, sha256 mismatches,
unreadable or wrongly sized images, unreadable ground truth) and otherwise returns a report of
what it checked, what it could not check (no known sum) and warnings (unrelated files, one line
per kind of file).

A file whose sha256 differs from the manifest's but whose content fingerprint matches the
manifest's (generated sets record both) is **within tolerance**: the same image rendered on a
processor whose floating point rounds differently (:mod:`homebench.data.fingerprint`). It is
reported as such, not as an error.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from homebench.data.database import GridDatabase
from homebench.data.fingerprint import fingerprint, matches
from homebench.data.generate import MANIFEST_NAME, is_generated
from homebench.data.manifest import Manifest, load_manifest
from homebench.data.posed import PosedDatabase, listed
from homebench.data.progress import over
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
    within_tolerance: tuple[str, ...] = ()

    generated: bool = False

    @property
    def n_images(self) -> int:
        return len(self.checked) + len(self.unchecked)

    def line(self, label: str) -> str:
        """What ``homebench data verify`` says of a database ``label`` that passed: how many
        files are identical, have no known sum, or (a generated set rendered on a processor
        that rounds otherwise, worded as the expected thing it is) are equal in content."""
        tolerated = len(self.within_tolerance)
        head = f"{label}: {self.n_images} images OK in {self.root}"
        unknown = f", {len(self.unchecked)} without a known sum" if self.unchecked else ""
        if self.generated and tolerated:
            return (
                f"{head}: a generated set, {len(self.checked) - tolerated} byte-identical to "
                f"the shipped reference and {tolerated} equal to it in content (fingerprints)"
                f"{unknown}; other bytes are expected where floating point rounds otherwise "
                "than on the reference machine: results are comparable, not bit-identical"
            )
        return (
            f"{head} ({len(self.checked) - tolerated} sha256 identical, {len(self.unchecked)} "
            "without a known sum"
            + (
                f", {tolerated} differing in bytes but matching their content fingerprint: made "
                "on a processor whose floating point rounds differently"
                if tolerated
                else ""
            )
            + ")"
        )


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
    checked, unchecked, warnings, mismatches, tolerated = [], [], [], [], []
    for kind, names in files.items():
        section = db.manifest.section(kind)
        for name, path in over(names.items(), len(names), f"sha256 {db.name} {kind}"):
            expected = section.files.get(name)
            relative = path.relative_to(db.root).as_posix()
            if expected is None:
                unchecked.append(relative)
                continue
            found = sha256_file(path)
            if found != expected:
                if _same_content(db, kind, name):
                    tolerated.append(relative)
                else:
                    mismatches.append((path, expected, found))
            checked.append(relative)
        for name in sorted(set(section.files) - set(names)):
            warnings.append(f"{section.relative_path(name)}: listed in the manifest, not used")
    if mismatches:
        raise ChecksumMismatchError(mismatches)
    for kind in db.kinds:
        for i, j in over(db.grid.indices(), db.grid.size, f"decode {db.name} {kind}"):
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
    warnings += _extra_file_warnings(db, [rel for rel in _all_files(db.root) if rel not in known])
    return VerifyReport(
        db.name, db.root, tuple(checked), tuple(unchecked), tuple(warnings), tuple(tolerated),
        generator is not None,
    )  # fmt: skip


def _same_content(db: GridDatabase, kind: str, name: str) -> bool:
    """Whether file ``name`` of ``kind`` matches its manifest fingerprint (False when the
    manifest has none or the file cannot be decoded)."""
    section = db.manifest.section(kind)
    reference = section.fingerprints.get(name)
    if reference is None:
        return False
    try:
        image = db.image(*section.parse_name(name), kind)
    except DataError:
        return False
    return matches(fingerprint(image), reference)


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


def _extra_file_warnings(db: GridDatabase, extra: list[str]) -> list[str]:
    """One warning per kind of file the manifest does not know: images of positions outside
    the grid (per image kind), and unrelated files; each with a count and a few names."""
    groups: dict[str, list[str]] = {}
    for relative in extra:
        kind = next((k for k in db.kinds if db.manifest.section(k).parse_path(relative)), None)
        what = f"{kind} images of positions outside the grid" if kind else "unrelated files"
        groups.setdefault(what, []).append(relative)
    return [f"{db.root}: {len(names)} {what}: {listed(names)}" for what, names in groups.items()]


def verify_posed(db: PosedDatabase) -> VerifyReport:
    """Verify a database of posed images (the Brains on Board format): every listed image
    present, in a known format, of the database's size and decodable, else the error naming
    the file; a warning for the files in its folder it does not list (those of rows left out
    for want of a pose are listed). The format records no sums: every image is reported
    without one."""
    db.check_images()
    for k in over(range(len(db)), len(db), f"decode {db.name}"):
        db.image(k)
    known = {*db.files, *db.own_files, *db.skipped_files}
    extra = [relative for relative in _all_files(db.root) if relative not in known]
    warnings = [f"{db.root}: {len(extra)} files not listed in {db.listing}: {listed(extra)}"]
    return VerifyReport(db.name, db.root, (), db.files, tuple(warnings if extra else ()))


def record_sums(manifest_path: Path, root: Path) -> Manifest:
    """Rewrite ``manifest_path``'s ``files`` and ``fingerprints`` with the sha256 and the
    content fingerprint of the images in ``root``.

    For a generated set ``root`` must hold a finished generation of the manifest's spec; the
    manifest's ``generator.key`` is set to the spec's current key. Comments in the file are
    not kept. Returns the new manifest.
    """
    manifest_path, root = Path(manifest_path), Path(root)
    manifest = load_manifest(manifest_path)
    if manifest.generator is not None and not is_generated(root, manifest.generator.spec):
        raise DataError(f"{root}: not a finished generation of {manifest_path}'s spec")
    db = GridDatabase(manifest, root)
    files = layout_files(db)
    data = manifest.model_dump(by_alias=True)
    for kind, names in files.items():
        section = manifest.section(kind)
        data["images"][kind]["files"] = {n: sha256_file(p) for n, p in sorted(names.items())}
        data["images"][kind]["fingerprints"] = {
            n: fingerprint(db.image(*section.parse_name(n), kind)) for n in sorted(names)
        }
    if manifest.generator is not None:
        data["generator"]["key"] = manifest.generator.spec.key()
    updated = Manifest.model_validate(data)
    write_text_atomic(manifest_path, updated.to_yaml())
    return updated
