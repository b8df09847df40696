"""The Brains on Board image-database format: panoramic images along routes and on grids.

The format of BoB robotics' ImageDatabase (C++ and Python), navbench, the Ant World databases
and the campus recordings of robot cars: a folder of images with

- ``database_entries.csv``: a header line, then one row per image, ``X [mm], Y [mm], Z [mm],
  Heading [degrees], Filename``, grid databases adding ``Grid X, Grid Y, Grid Z``, extra sensor
  columns after them, a space after each comma (:mod:`.entries`);
- ``database_metadata.yaml``: OpenCV FileStorage YAML starting ``%YAML:1.0``: the type (grid or
  route), the camera and its resolution, whether the images need unwrapping
  (:mod:`.metadata`, read by :mod:`.filestorage`);
- optionally ``homebench.yaml``: what the metadata does not say (:mod:`.overrides`).

:func:`open_bob` reads a folder as a :class:`~homebench.data.posed.PosedDatabase` (metres,
degrees; a grid one also as a :class:`~homebench.data.database.GridDatabase`: :mod:`.grid`;
rows without a pose left out or filled: :mod:`.gaps`), :func:`write_bob`
writes a grid database in the format. No manifest is needed: the data commands and
:func:`homebench.data.catalog.resolve` take the folder wherever a database is named.
"""

from homebench.data.bob.layout import ENTRIES_NAME, METADATA_NAME, OVERRIDES_NAME, is_bob_folder
from homebench.data.bob.overrides import BobOverrides
from homebench.data.bob.reader import open_bob
from homebench.data.bob.writer import write_bob

__all__ = [
    "ENTRIES_NAME",
    "METADATA_NAME",
    "OVERRIDES_NAME",
    "BobOverrides",
    "is_bob_folder",
    "open_bob",
    "write_bob",
]
