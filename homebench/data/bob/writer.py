"""Write a grid database in the Brains on Board image-database format.

The folder holds what BoB's ImageDatabase (and navbench) reads: the images under BoB's grid
file names (``image_+000300_+000600_+001000.png``: the position in mm),
``database_entries.csv`` (``X [mm], Y [mm], Z [mm], Heading [degrees], Filename, Grid X, Grid Y,
Grid Z``, x fastest, as BoB's grid recorder writes it; headings as BoB writes them, compass
bearings: :mod:`.conventions`) and ``database_metadata.yaml`` (OpenCV FileStorage YAML: type,
grid, camera resolution, needsUnwrapping), with ``homebench.yaml`` holding the exact camera
model and the headings' convention, so that homebench reads back what it wrote: the same
image bytes, poses and camera model. Every image is labelled with the position it was taken
at (``grid.order: as-written``). One image kind is written: the unfolded panoramas, or the raw
images of a database that has none. Z is the camera height of a generated world, else 0.

The folder is built under a temporary name and renamed into place; an existing folder that is
not empty is never written to.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml

from homebench.data.bob.conventions import BOB_HEADINGS
from homebench.data.bob.layout import ENTRIES_NAME, METADATA_NAME, OVERRIDES_NAME
from homebench.data.bob.overrides import BobOverrides
from homebench.data.database import GridDatabase
from homebench.data.manifest import CatadioptricSection, PanoramaSection
from homebench.errors import DataError
from homebench.fileio import atomic_directory
from homebench.geometry import CatadioptricGeometry, grid_key

HEADER = "X [mm], Y [mm], Z [mm], Heading [degrees], Filename, Grid X, Grid Y, Grid Z"


def write_bob(db: GridDatabase, out: Path) -> Path:
    """Write ``db`` to the new folder ``out`` in the Brains on Board format; ``out``.
    DataError when ``out`` exists and is not an empty folder, or an image is missing."""
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise DataError(f"{out}: exists and is not empty; remove it or choose another folder")
    kind = "unfolded" if "unfolded" in db.kinds else "raw"
    db.check_layout((kind,))
    generator = db.manifest.generator
    z_mm = generator.spec.camera_height * 1000.0 if generator is not None else 0.0
    nx, ny = db.grid.shape
    rows = [HEADER]
    with atomic_directory(out) as folder:
        for j in range(ny):
            for i in range(nx):
                x, y = db.grid.position(i, j) * 1000.0
                source = db.path(i, j, kind)
                name = file_name(x, y, z_mm, source.suffix)
                if (folder / name).exists():
                    raise DataError(
                        f"{out}: two grid positions round to the file name {name}: BoB names "
                        "grid images by their position in whole millimetres"
                    )
                shutil.copyfile(source, folder / name)
                world = db.manifest.headings_deg.get(grid_key(i, j), db.manifest.heading_deg)
                heading = float(BOB_HEADINGS.from_world_deg(world)) % 360.0
                values = [number(v) for v in (x, y, z_mm, heading)]
                rows.append(", ".join([*values, name, str(i), str(j), "0"]))
        (folder / ENTRIES_NAME).write_text("\n".join(rows) + "\n", encoding="utf-8")
        (folder / METADATA_NAME).write_text(_metadata(db, kind, z_mm), encoding="utf-8")
        (folder / OVERRIDES_NAME).write_text(_overrides(db, kind), encoding="utf-8")
    return out


def number(value: float) -> str:
    """``value`` with 12 significant digits, no trailing zeros: 900 for 900.0000000000001."""
    return f"{value:.12g}"


def file_name(x_mm: float, y_mm: float, z_mm: float, suffix: str) -> str:
    """BoB's name of a grid image at (x, y, z) mm: ``image_+000300_-000600_+001000.png``."""
    return "image_" + "_".join(f"{round(v):+07d}" for v in (x_mm, y_mm, z_mm)) + suffix


def _metadata(db: GridDatabase, kind: str, z_mm: float) -> str:
    """``database_metadata.yaml`` as BoB's grid recorder writes it."""
    (nx, ny), (width, height) = db.grid.shape, db.manifest.section(kind).size
    x0, y0 = (number(v * 1000.0) for v in db.grid.origin)
    spacing, raw = number(db.grid.spacing * 1000.0), int(kind == "raw")
    return (
        "%YAML:1.0\n---\nmetadata:\n   type: grid\n   grid:\n"
        f"      beginAtMM: [ {x0}, {y0}, {number(z_mm)} ]\n"
        f"      separationMM: [ {spacing}, {spacing}, 0 ]\n"
        f"      size: [ {nx}, {ny}, 1 ]\n"
        f"   camera:\n      name: homebench\n      resolution: [ {width}, {height} ]\n"
        f"      isPanoramic: {raw}\n   needsUnwrapping: {raw}\n"
    )


def _overrides(db: GridDatabase, kind: str) -> str:
    """``homebench.yaml``: the database's name, description, the headings' convention, the
    labels' order and the exact camera model."""
    geometry = db.geometry(kind)
    if isinstance(geometry, CatadioptricGeometry):
        images = {"raw": {"catadioptric": CatadioptricSection.from_geometry(geometry)}}
    else:
        images = {"unfolded": {"panorama": PanoramaSection.from_geometry(geometry).model_dump()}}
    headings = {"zero_deg": BOB_HEADINGS.zero_deg, "direction": BOB_HEADINGS.direction}
    overrides = BobOverrides.model_validate(
        {
            "name": db.name,
            "description": db.manifest.description,
            "headings": headings,
            "grid": {"order": "as-written"},
            "images": images,
        }
    )
    data = overrides.model_dump(mode="json", exclude_none=True)
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)
