"""The one exception root of homebench and its families.

The CLI turns every :class:`HomebenchError` into one line (``str(error)``) and exit code 2
(:class:`Interrupted`: 130, as a shell reports a command stopped by Ctrl-C); anything else is
a crash (exit 1). Each error names the file or key it is about.
"""

from __future__ import annotations

from pathlib import Path


class HomebenchError(Exception):
    """Root of every error homebench raises on purpose (bad input, bad data, bad config)."""


class Interrupted(HomebenchError):
    """The user stopped a run (Ctrl-C): what finished is saved, and a rerun resumes; the
    message says how much that is."""


class ConfigError(HomebenchError):
    """A run config, world spec or manifest is invalid; the message names the file and key path."""


class DataError(HomebenchError):
    """A grid database is missing, incomplete, corrupt or inconsistent."""


class WriteError(DataError):
    """A file or folder that cannot be written (a full disk, a read-only file system, a file
    where a folder should be): the environment's fault, never a job's, so it stops a run
    without recording any job as failed."""


class UnknownDatabaseError(DataError):
    """A database name that no manifest describes."""


class MissingImagesError(DataError):
    """Grid positions whose image file is not there."""

    def __init__(self, folder: Path, positions: list[tuple[int, int]]):
        shown = ", ".join(f"({i},{j})" for i, j in positions[:10])
        more = f" and {len(positions) - 10} more" if len(positions) > 10 else ""
        super().__init__(f"{folder}: no image for grid position(s) {shown}{more}")
        self.folder = folder
        self.positions = positions


class CorruptImageError(DataError):
    """An image file that exists but cannot be decoded (truncated, zero bytes, not an image)."""

    def __init__(self, path: Path, reason: str = "cannot be decoded as an image"):
        super().__init__(f"{path}: {reason}")
        self.path = path


class ImageSizeError(DataError):
    """An image whose size differs from the one its database declares."""

    def __init__(self, path: Path, expected: tuple[int, int], found: tuple[int, int]):
        super().__init__(
            f"{path}: image is {found[0]}x{found[1]} (width x height), "
            f"expected {expected[0]}x{expected[1]}"
        )
        self.path = path


class ChecksumMismatchError(DataError):
    """Files whose sha256 differs from the manifest's."""

    def __init__(self, mismatches: list[tuple[Path, str, str]]):
        path, expected, found = mismatches[0]
        more = f" (and {len(mismatches) - 1} more files)" if len(mismatches) > 1 else ""
        super().__init__(
            f"{path}: sha256 mismatch, expected {expected[:12]}…, found {found[:12]}…{more}"
        )
        self.mismatches = mismatches
