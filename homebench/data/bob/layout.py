"""The files of a Brains on Board image database, and reading them within bounds."""

from __future__ import annotations

from pathlib import Path

from homebench.errors import DataError
from homebench.fileio import open_regular

#: One row per image: position (mm), heading (degrees), file name, grid index of grid databases.
ENTRIES_NAME = "database_entries.csv"
#: OpenCV FileStorage YAML: the database's type, camera, resolution, whether images need unwrapping.
METADATA_NAME = "database_metadata.yaml"
#: homebench's own, optional: what the metadata does not say (:mod:`.overrides`).
OVERRIDES_NAME = "homebench.yaml"
#: The files that describe the database rather than hold its images.
DESCRIPTION_FILES = (ENTRIES_NAME, METADATA_NAME, OVERRIDES_NAME)


def is_bob_folder(path: Path) -> bool:
    """Whether ``path`` is a folder holding a ``database_entries.csv``."""
    return (Path(path) / ENTRIES_NAME).is_file()


def read_text(path: Path, limit: int, what: str) -> str:
    """The UTF-8 text (a leading byte-order mark dropped) of the regular file ``path`` of at
    most ``limit`` bytes; DataError naming the file otherwise (nothing is read from a FIFO,
    a device or a folder)."""
    try:
        with open_regular(path) as f:
            data = f.read(limit + 1)
    except FileNotFoundError:
        raise DataError(f"{path}: no such {what}") from None
    except OSError as error:
        raise DataError(f"{path}: cannot read the {what} ({error.strerror or error})") from None
    if len(data) > limit:
        raise DataError(f"{path}: the {what} is larger than the {limit / (1 << 20):g} MiB limit")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise DataError(f"{path}: the {what} is not UTF-8 text ({error})") from None
