"""Do a run's images match their reference sums? Checked once per run, from cached hashes.

- A **generated set named by a shipped manifest** (``synth-original``) is generated on this
  machine; its folder's manifest holds this machine's sums and fingerprints, the shipped one
  those of the reference machine. They are compared as manifests (nothing is read): files
  with equal sums are identical; files whose bytes differ but whose content fingerprints match
  come from a processor that rounds differently (:mod:`homebench.data.fingerprint`): results
  are comparable, not bit-identical; anything else differs in content.
- A **real set** whose manifest lists sums: each file's sha256 (cached by size and mtime, see
  :mod:`homebench.data.file_hashes`) against the manifest's.
- Every database: an image kind whose ``pattern`` names no file (:func:`pattern_notes`), and
  where its own files disagree (:func:`database_warnings`: a Brains on Board folder's metadata
  and entries).

The outcome is a note for the user where files differ in content (bytes alone differing is
expected of a generated set and not repeated on every run: ``homebench data verify`` says
it), or a warning where a database's own files disagree (never an error: the run may go on,
but its numbers are not the reference's); the sums' comparison goes into ``environment.json``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from homebench.config import SweptWorld
from homebench.data import catalog
from homebench.data.database import GridDatabase
from homebench.data.file_hashes import file_hashes
from homebench.data.fingerprint import matches
from homebench.data.manifest import Manifest
from homebench.data.naming import database_label
from homebench.errors import UnknownDatabaseError
from homebench.evaluation.sources import Source, open_source


@dataclass(frozen=True)
class DataCheck:
    """How a database's files compare with their reference sums: ``identical`` in bytes,
    ``tolerated`` (bytes differ, content fingerprint matches), ``differing`` (file names, in
    content), of ``checked`` files with a reference sum."""

    database: str
    reference: str
    checked: int
    identical: int
    tolerated: int
    differing: tuple[str, ...]

    def note(self) -> str | None:
        """One line for the user, or None when no file differs in content: bytes that differ
        with the content equal are what a generated set looks like on a processor that rounds
        otherwise, expected, recorded in ``environment.json`` and said by ``homebench data
        verify`` rather than by every run."""
        if not self.differing:
            return None
        parts = [f"{self.identical} of {self.checked} files byte-identical to {self.reference}"]
        if self.tolerated:
            parts.append(
                f"{self.tolerated} differ in bytes but match their content fingerprints (this "
                "processor's floating point rounds differently: results are comparable, not "
                "bit-identical)"
            )
        if self.differing:
            shown = ", ".join(self.differing[:3])
            more = f" and {len(self.differing) - 3} more" if len(self.differing) > 3 else ""
            parts.append(
                f"{len(self.differing)} differ in content ({shown}{more}): these are not the "
                "reference's images, and results are not comparable with its reports"
            )
        return f"{self.database}: " + "; ".join(parts)

    def as_dict(self) -> dict[str, object]:
        return {
            "reference": self.reference,
            "checked": self.checked,
            "identical": self.identical,
            "tolerated": self.tolerated,
            "differing": list(self.differing),
        }


def _compare_manifests(name: str, generated: Manifest, reference: Manifest) -> DataCheck:
    checked = identical = tolerated = 0
    differing = []
    for kind in generated.kinds:
        ours, theirs = generated.section(kind), reference.section(kind)
        for file_name, expected in theirs.files.items():
            found = ours.files.get(file_name)
            if expected is None or found is None:
                continue
            checked += 1
            if found == expected:
                identical += 1
            elif (
                file_name in ours.fingerprints
                and file_name in theirs.fingerprints
                and matches(ours.fingerprints[file_name], theirs.fingerprints[file_name])
            ):
                tolerated += 1
            else:
                differing.append(ours.relative_path(file_name))
    return DataCheck(
        name, "the shipped reference sums", checked, identical, tolerated, tuple(differing)
    )


def _check_files(name: str, source: Source) -> DataCheck:
    database = open_source(source)
    paths, expected = {}, {}
    for kind in database.kinds:
        section = database.manifest.section(kind)
        for file_name, sha in section.files.items():
            if sha is None:
                continue
            path = database.root / section.relative_path(file_name)
            if path.is_file():
                paths[path], expected[path] = section.relative_path(file_name), sha
    found = file_hashes(paths)
    differing = tuple(paths[p] for p in paths if found[p] != expected[p])
    identical = len(paths) - len(differing)
    return DataCheck(name, "the manifest's sums", len(paths), identical, 0, differing)


def check_source(source: Source) -> DataCheck | None:
    """The reference check of one database of a run (None: it has no reference sums)."""
    manifest = open_source(source).manifest
    if manifest.generator is None:
        has_sums = any(v for k in manifest.kinds for v in manifest.section(k).files.values())
        return _check_files(source.alias, source) if has_sums else None
    try:
        reference, folder = catalog.find_manifest(source.locator)
    except UnknownDatabaseError:
        return None
    if folder is not None or reference.generator is None:
        return None  # a generated folder or manifest file of its own: no reference
    if reference.generator.key != manifest.generator.key:
        return None  # another world than the reference's (a swept seed or style)
    return _compare_manifests(source.alias, manifest, reference)


def pattern_notes(sources: dict[tuple[str, SweptWorld], Source]) -> list[str]:
    """One note per image kind of a run's database whose pattern names no file (see
    :meth:`~homebench.data.database.GridDatabase.unmatched_patterns`): a kind the run does not
    read is not checked by it, and a mistyped pattern would stay unseen."""
    return [f"{name}: {line}" for name, db in _databases(sources) for line in
            db.unmatched_patterns()]  # fmt: skip


def database_warnings(sources: dict[tuple[str, SweptWorld], Source]) -> list[str]:
    """The warnings of a run's databases on their own files (see
    :attr:`~homebench.data.database.GridDatabase.warnings`), one line each."""
    return [f"{name}: {line}" for name, db in _databases(sources) for line in db.warnings]


def _databases(sources: dict[tuple[str, SweptWorld], Source]) -> Iterator[tuple[str, GridDatabase]]:
    """Each database of a run once, named as its notes name it: ``database 'alias', label``."""
    for source in {s.alias: s for s in sources.values()}.values():
        database = open_source(source)
        yield (
            f"database {source.alias!r}, {database_label(database.name, source.locator)}",
            database,
        )
