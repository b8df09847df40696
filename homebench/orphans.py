"""Temporary files and folders of atomic writes: their names, their locks, their orphans.

:func:`homebench.fileio.atomic_write` and :func:`~homebench.fileio.atomic_directory` build a
file or folder under a temporary name beside its final one, ``.<final name>.<8 random
characters>.homebench.tmp``, and rename it when it is complete. A process killed meanwhile
(SIGKILL, the OOM killer, a power cut) leaves the temporary behind: an orphan, such as a
half-generated world folder. The first time a process makes a temporary in a folder, it removes
the orphans there (:func:`sweep_once`): so the next run or generation cleans up after a killed
one.

While a temporary is being built its process holds an exclusive ``flock`` on it, and the kernel
drops that lock when the process ends, however it ends: a locked temporary belongs to a live
process and is never touched (see :func:`remove_orphans` for the whole rule).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import re
import shutil
import stat
import time
from collections.abc import Iterator
from pathlib import Path

#: The end of every temporary name (the tempfile module puts 8 random characters before it).
TMP_SUFFIX = ".homebench.tmp"
_TMP_NAME = re.compile(r"\..+\.[a-z0-9_]{8}" + re.escape(TMP_SUFFIX))
#: A temporary unchanged for this long (seconds) and not locked is an orphan. The lock alone
#: tells a live writer; the age covers the instant between making a temporary and locking it.
ORPHAN_AGE_S = 10 * 60

_swept: set[Path] = set()


def lock(fd: int) -> None:
    """Hold an exclusive lock on the temporary open as ``fd`` until ``fd`` is closed.

    On a file system without locks nothing is held; :func:`remove_orphans` cannot take the
    lock there either, so it removes nothing there.
    """
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
    except OSError as error:
        if error.errno not in (errno.ENOLCK, errno.EOPNOTSUPP):
            raise


@contextlib.contextmanager
def locked_folder(folder: Path) -> Iterator[None]:
    """Hold the lock of the temporary ``folder`` for the duration of the block."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        lock(fd)
        yield
    finally:
        os.close(fd)


def sweep_once(folder: Path) -> None:
    """Remove the orphans in ``folder``, the first time this process calls this for it."""
    folder = Path(os.path.abspath(folder))
    if folder not in _swept:
        _swept.add(folder)
        remove_orphans(folder)


def remove_orphans(folder: Path, min_age: float = ORPHAN_AGE_S) -> list[Path]:
    """Remove the orphan temporaries directly in ``folder``; return them.

    An entry is removed only if all of these hold:

    - its name is a temporary name (``.<name>.<8 characters>.homebench.tmp``: nothing another
      program made), and it is a regular file or a folder, not a symbolic link;
    - it has not been modified for ``min_age`` seconds;
    - no process holds its lock: the removal takes the lock itself (without waiting) and
      deletes the entry while holding it, so a writer that is alive (another run's worker,
      another process generating the same world, however long it takes) keeps its temporary.

    Entries that vanish or cannot be removed meanwhile are left alone.
    """
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return []
    removed = []
    now = time.time()
    for entry in entries:
        if not _TMP_NAME.fullmatch(entry.name):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        kind_ok = stat.S_ISREG(info.st_mode) or stat.S_ISDIR(info.st_mode)
        if kind_ok and now - info.st_mtime >= min_age and _remove_unlocked(Path(entry.path)):
            removed.append(Path(entry.path))
    return removed


def _remove_unlocked(path: Path) -> bool:
    """Delete the file or folder ``path`` if its lock is free, holding the lock meanwhile."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # BlockingIOError: a live writer
        if stat.S_ISDIR(os.fstat(fd).st_mode):
            shutil.rmtree(path)
        else:
            path.unlink()
    except OSError:
        return False
    finally:
        os.close(fd)
    return True
