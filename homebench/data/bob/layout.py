"""The files of a Brains on Board image database."""

from __future__ import annotations

from pathlib import Path

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
