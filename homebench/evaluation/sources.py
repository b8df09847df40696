"""The databases of a run as workers see them: paths and identities, opened lazily per process.

A :class:`Source` is small and picklable; :func:`open_source` turns it into a
:class:`~homebench.data.database.GridDatabase` once per process. Generated worlds are generated
(or found in the cache) when the run is prepared, before any job starts.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from homebench.config import DatabaseRef, RunConfig
from homebench.data import catalog
from homebench.data.database import GridDatabase
from homebench.data.generate import generate
from homebench.errors import DataError
from homebench.geometry import Grid, PanoramaGeometry
from homebench.hashing import stable_hash
from homebench.imaging.projection import unfold
from homebench.imaging.rotation import rotate_view
from homebench.methods.base import ImageKind, View


@dataclass(frozen=True)
class Source:
    """One database of a run. ``identity`` names its images in every cache and job key.

    ``locator`` is what :func:`homebench.data.catalog.resolve` takes (a known name, a manifest
    file or a database folder) and ``path`` the folder of a real set's images, if given.
    """

    alias: str
    identity: str
    locator: str
    path: Path | None
    grid: Grid
    unfold_geometry: PanoramaGeometry | None  # to unfold raw images when there are no unfolded

    @property
    def columns(self) -> int:
        """Columns of the unfolded views methods see (whole-column rotations use it)."""
        if self.unfold_geometry is not None:
            return self.unfold_geometry.width
        geometry = open_source(self).geometry("unfolded")
        assert isinstance(geometry, PanoramaGeometry)
        return geometry.width


def _prepare(alias: str, ref: DatabaseRef, config: RunConfig, jobs: int) -> Source:
    if ref.world is not None:
        locator, path = str(generate(ref.world, jobs=jobs, name=alias)), None
        database = catalog.resolve(locator)
    else:
        assert ref.name is not None
        locator, path = ref.name, ref.path
        manifest, _ = catalog.find_manifest(locator)
        if manifest.generator is not None:
            database = catalog.ensure_generated(locator, jobs=jobs)
        else:
            database = catalog.resolve(locator, path)
    database.check_layout()
    manifest = database.manifest
    identity = (
        f"{manifest.name}-{manifest.generator.spec.key()}"
        if manifest.generator is not None
        else f"{manifest.name}-{stable_hash(str(database.root.resolve()), 12)}"
    )
    needs_unfold = "unfolded" not in manifest.kinds
    return Source(
        alias=alias,
        identity=identity,
        locator=locator,
        path=path,
        grid=database.grid,
        unfold_geometry=config.unfold.geometry() if needs_unfold else None,
    )


def prepare_sources(config: RunConfig, jobs: int) -> dict[str, Source]:
    """Sources of every database alias used by a condition (generating worlds as needed)."""
    used = {alias for _, current, goal in config.condition_pairs() for alias in (current, goal)}
    return {
        alias: _prepare(alias, ref, config, jobs)
        for alias, ref in config.databases.items()
        if alias in used
    }


@lru_cache(maxsize=32)
def open_source(source: Source) -> GridDatabase:
    """The database of a source, opened once per process."""
    return catalog.resolve(source.locator, source.path)


def load_view(source: Source, i: int, j: int, kind: ImageKind, rotation: float = 0.0) -> View:
    """The view of (i, j) a method of ``kind`` needs, turned by ``rotation`` (radians, ccw).

    Raw-only databases give unfolded views by unfolding (``source.unfold_geometry``); a method
    that needs raw images on a database without them is a DataError.
    """
    database = open_source(source)
    if kind in database.kinds:
        view = database.view(i, j, kind)
    elif kind == "unfolded" and source.unfold_geometry is not None:
        raw = database.view(i, j, "raw")
        image = unfold(raw.image, raw.geometry, source.unfold_geometry)
        view = View(image, source.unfold_geometry)
    else:
        raise DataError(
            f"database {database.name!r} has no {kind!r} images (it has: "
            f"{', '.join(database.kinds)})"
        )
    return rotate_view(view, rotation) if rotation else view
