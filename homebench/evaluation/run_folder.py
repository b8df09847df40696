"""One run folder, one run: an OS lock while a run uses it, and the config it belongs to.

A run holds ``.homebench.lock`` with ``fcntl.flock`` for as long as it runs: exclusively, or
shared by the shards of one run (which may run at once). The kernel releases the lock when the
process ends, however it ends. A second run into a folder in use is refused at once.

A folder belongs to the config whose ``config.resolved.json`` it holds. A run of another config
(any difference but the execution settings :data:`EXECUTION_KEYS`) is refused unless forced,
which replaces the run. The check and the metadata writes happen under a short exclusive
``.homebench.claim`` lock, so two shards starting together cannot both claim the folder.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from homebench.errors import ConfigError, DataError, HomebenchError
from homebench.fileio import make_folder, parse_json, read_record_text
from homebench.hashing import stable_hash

CONFIG_FILE = "config.resolved.json"
LOCK_FILE = ".homebench.lock"
CLAIM_FILE = ".homebench.claim"
#: Settings of how a run executes, not of what it computes: they may change between runs.
EXECUTION_KEYS = ("jobs", "job_timeout_s", "worker_memory_mb", "checks")
#: How long a run waits for another one to finish claiming the folder.
CLAIM_WAIT_S = 60.0


class RunFolderInUseError(HomebenchError):
    """Another homebench run holds the folder."""


def _open(path: Path) -> int:
    """The lock file ``path`` in a run folder, opened (the folder made where missing)."""
    make_folder(path.parent)
    try:
        return os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as error:
        raise DataError(f"{path}: cannot use the run folder ({error.strerror or error})") from None


def _flock(fd: int, operation: int) -> bool:
    try:
        fcntl.flock(fd, operation | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def _first_missing(folder: Path) -> Path | None:
    """The outermost of ``folder`` and its parents that does not exist (None: it exists)."""
    missing = None
    while not folder.exists() and folder != folder.parent:
        missing, folder = folder, folder.parent
    return missing


def _remove_if_unused(run_dir: Path, made: Path | None) -> None:
    """Remove the lock files of a run that wrote nothing else into ``run_dir``, and the
    folders up to ``made`` (the outermost one the run created, if any) that are then empty."""
    try:
        entries = set(os.listdir(run_dir))
        if not entries <= {LOCK_FILE, CLAIM_FILE}:
            return
        for name in entries:
            (run_dir / name).unlink()
        if made is None:
            return
        for folder in (run_dir, *run_dir.parents):
            folder.rmdir()
            if folder == made:
                return
    except OSError:  # another process's file, a folder not empty: leave it
        return


@contextlib.contextmanager
def lock_run_folder(run_dir: Path, shared: bool = False) -> Iterator[None]:
    """Hold the run folder's lock (``shared``: one shard of a run); RunFolderInUseError if
    another run holds it. A run that ends in an error before it wrote anything but its locks
    leaves no trace: an exclusive holder then removes the locks, and the folders the lock
    file made (a shard never removes what other shards may use)."""
    run_dir = Path(run_dir)
    made = _first_missing(run_dir)
    path = run_dir / LOCK_FILE
    fd = _open(path)
    try:
        if not _flock(fd, fcntl.LOCK_SH if shared else fcntl.LOCK_EX):
            raise RunFolderInUseError(
                f"{run_dir}: in use by another homebench run (it holds {path}); "
                "wait for it to end or choose another output folder"
            )
        try:
            yield
        except BaseException:
            if not shared:
                _remove_if_unused(run_dir, made)
            raise
    finally:
        os.close(fd)


@contextlib.contextmanager
def claim_run_folder(run_dir: Path) -> Iterator[None]:
    """Hold the short exclusive claim lock (waiting up to :data:`CLAIM_WAIT_S` for it)."""
    fd = _open(Path(run_dir) / CLAIM_FILE)
    try:
        deadline = time.monotonic() + CLAIM_WAIT_S
        while not _flock(fd, fcntl.LOCK_EX):
            if time.monotonic() > deadline:
                raise RunFolderInUseError(f"{run_dir}: another homebench run keeps claiming it")
            time.sleep(0.1)
        yield
    finally:
        os.close(fd)


def _what_counts(resolved: dict[str, Any]) -> dict[str, Any]:
    return {key: value for key, value in resolved.items() if key not in EXECUTION_KEYS}


def _first_difference(old: Any, new: Any, where: str = "") -> str:
    if isinstance(old, dict) and isinstance(new, dict):
        for key in sorted(old.keys() | new.keys(), key=str):
            if old.get(key) != new.get(key):
                return _first_difference(old.get(key), new.get(key), f"{where}.{key}".lstrip("."))
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        for k, (a, b) in enumerate(zip(old, new, strict=True)):
            if a != b:
                return _first_difference(a, b, f"{where}.{k}".lstrip("."))
    return f"{where or 'the config'}: {json.dumps(old)} there, {json.dumps(new)} now"


def check_owner(
    run_dir: Path, resolved: dict[str, Any], take_over: bool, can_update: bool = True
) -> None:
    """ConfigError unless ``run_dir`` is new, or holds a run of the config ``resolved``, or
    ``take_over`` (``--update`` or ``--force``); the error names the file to look at and the
    first difference, and offers ``--update`` where the run ``can_update`` (a grid run)."""
    path = Path(run_dir) / CONFIG_FILE
    if take_over or not path.exists():
        return
    try:
        previous = parse_json(read_record_text(path))
    except (OSError, ValueError) as error:
        raise DataError(
            f"{path}: unreadable ({error}); choose another output folder, or --force to "
            "replace the run it belonged to"
        ) from None
    difference = "not a config"
    if isinstance(previous, dict):
        old, new = _what_counts(previous), _what_counts(resolved)
        if stable_hash(old) == stable_hash(new):
            return
        difference = _first_difference(old, new)
    update = (
        "--update to make it this config's run (keeps every result whose job is unchanged), or "
        if can_update
        else "or "
    )
    raise ConfigError(
        f"{run_dir}: holds the run of another config (see {path}; {difference}); choose "
        f"another output folder, {update}--force to replace that run (recomputes every job)"
    )
