"""A report is built again only when something it is made from changed.

The key of a report hashes everything that decides its bytes: the run folder's files (all but
``features/``, hidden files and the report's own folder; ``environment.json`` without
:data:`STAMPS`, which every ``homebench run`` call renews), the report's arguments, the source of
every module of the homebench package (the report code and all it may import: reading them is
cheaper than finding which it imports) and the versions of the libraries that draw. A complete
report stores its key and the files it wrote in :data:`KEY_FILE` beside them; a report whose
stored key matches and whose files are all there is reused as it is. So a rerun that changed no
result keeps its report, whose date and command are those of the call that built it.
"""

from __future__ import annotations

import hashlib
import json
from importlib import metadata
from pathlib import Path
from typing import Any

import homebench
from homebench import __version__
from homebench.fileio import write_text_atomic

KEY_FILE = "report-inputs.json"
#: Fields of ``environment.json`` that say which call wrote it, not what the run holds (the
#: host's load changes with every call, even one that times no job: a report kept then still
#: shows the load of the call that timed its jobs).
STAMPS = ("started", "command", "load")
#: Libraries whose version can change a report's bytes.
LIBRARIES = ("matplotlib", "numpy", "pandas", "pillow", "fonttools")
SKIPPED = ("features",)


def _file_bytes(path: Path, relative: str) -> bytes:
    """What of a run folder's file the key hashes: its bytes, ``environment.json`` without
    :data:`STAMPS` (the bytes as they are when it is not a JSON object)."""
    data = path.read_bytes()
    if relative != "environment.json":
        return data
    try:
        environment = json.loads(data)
    except ValueError:
        return data
    if not isinstance(environment, dict):
        return data
    kept = {k: v for k, v in environment.items() if k not in STAMPS}
    return json.dumps(kept, sort_keys=True).encode()


def _run_files(run_dir: Path, folder: Path) -> list[tuple[str, Path]]:
    """(relative POSIX path, path) of the run folder's files a report may read, sorted (none
    when it is no folder: building the report then says what is wrong)."""
    if not run_dir.is_dir():
        return []
    skipped = {folder.resolve(), *((run_dir / name).resolve() for name in SKIPPED)}
    found = []
    todo = [run_dir]
    while todo:
        here = todo.pop()
        for path in here.iterdir():
            if path.name.startswith(".") or path.resolve() in skipped:
                continue
            if path.is_dir():
                todo.append(path)
            elif path.is_file():
                found.append((path.relative_to(run_dir).as_posix(), path))
    return sorted(found)


def _library_versions() -> dict[str, str]:
    versions = {}
    for name in LIBRARIES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "none"
    return versions


def report_key(run_dir: Path, folder: Path, arguments: dict[str, Any]) -> str:
    """The sha256 of the inputs of the report of ``run_dir`` written to ``folder`` with
    ``arguments`` (JSON values)."""
    digest = hashlib.sha256()
    head = {"homebench": __version__, "libraries": _library_versions(), "arguments": arguments}
    digest.update(json.dumps(head, sort_keys=True).encode() + b"\0")
    package = Path(homebench.__file__).parent
    for path in sorted(package.rglob("*.py")):
        source = path.read_bytes()
        name = path.relative_to(package).as_posix()
        digest.update(f"code {name}\0{len(source)}\0".encode() + source)
    for relative, path in _run_files(Path(run_dir), Path(folder)):
        data = _file_bytes(path, relative)
        digest.update(f"file {relative}\0{len(data)}\0".encode() + data)
    return digest.hexdigest()


def reusable(folder: Path, key: str) -> tuple[list[Path], list[str]] | None:
    """The files and warnings of the complete report in ``folder`` built from inputs of
    ``key``, or None (another key, no record, or a file gone)."""
    try:
        record = json.loads((Path(folder) / KEY_FILE).read_text(encoding="utf-8"))
        stored, files, warnings = record["key"], record["files"], record["warnings"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    paths = [Path(folder) / name for name in files]
    if stored != key or not all(path.is_file() for path in paths):
        return None
    return paths, list(warnings)


def forget(folder: Path) -> None:
    """Drop the record of ``folder``'s report (before it is rebuilt)."""
    (Path(folder) / KEY_FILE).unlink(missing_ok=True)


def remember(folder: Path, key: str, files: list[Path], warnings: list[str]) -> None:
    """Record that the report in ``folder`` (its ``files``, inside it) is complete for ``key``."""
    names = [path.relative_to(folder).as_posix() for path in files]
    record = {"key": key, "files": names, "warnings": warnings}
    write_text_atomic(Path(folder) / KEY_FILE, json.dumps(record, indent=1) + "\n")
