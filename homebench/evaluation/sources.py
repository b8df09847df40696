"""The databases of a run as workers see them: paths and identities, opened lazily per process.

A :class:`Source` is small and picklable; :func:`open_source` turns it into a
:class:`~homebench.data.database.GridDatabase` once per process. Generated worlds are generated
(or found in the cache) when the run is prepared, before any job starts; so are the checks that
every method can get its kind of image from every database, and that every image the run will
read is there, in a known format, of the manifest's size and not cut short (read from the
headers: nothing is decoded).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from homebench.config import DatabaseRef, RunConfig, SweptWorld
from homebench.data import catalog
from homebench.data.bob import BobOverrides
from homebench.data.database import GridDatabase
from homebench.data.file_hashes import file_hashes
from homebench.data.generate import Generation, generate_many
from homebench.data.manifest import KINDS, Manifest
from homebench.data.naming import database_label
from homebench.data.synth.spec import WorldSpec
from homebench.errors import ConfigError, DataError
from homebench.geometry import Grid, PanoramaGeometry, Places, missing_positions
from homebench.hashing import stable_hash
from homebench.imaging.projection import unfold
from homebench.imaging.rotation import rotate_view
from homebench.methods import registry
from homebench.views import ImageKind, View


@dataclass(frozen=True)
class Source:
    """One database of a run. ``identity`` names its images in every cache and job key (a
    generated set's spec key, a real set's folder: each image's content is in the keys too).
    ``database_key`` says what the database holds, wherever it is: the manifest's name and the
    spec key, or for a real set the key of its images' content (:func:`content_key`); runs
    hold the same pairs only where these are equal.

    ``locator`` is what :func:`homebench.data.catalog.resolve` takes (a known name, a manifest
    file or a database folder), ``path`` the folder of a real set's images, if given, and
    ``overrides`` what the config states of a Brains on Board folder's camera.
    """

    alias: str
    identity: str
    database_key: str
    locator: str
    path: Path | None
    grid: Grid
    unfold_geometry: PanoramaGeometry | None  # to unfold raw images when there are no unfolded
    seed: int | None = None  # the world's seed for generated sets
    style: str | None = None  # the world's style for generated sets
    overrides: BobOverrides | None = None

    @property
    def columns(self) -> int:
        """Columns of the unfolded views methods see (whole-column rotations use it)."""
        if self.unfold_geometry is not None:
            return self.unfold_geometry.width
        geometry = open_source(self).geometry("unfolded")
        assert isinstance(geometry, PanoramaGeometry)
        return geometry.width


def _in_world(spec: WorldSpec, world: SweptWorld) -> WorldSpec:
    """``spec`` with the swept world's style and seed (where swept)."""
    style, seed = world
    update = {k: v for k, v in (("style", style), ("seed", seed)) if v is not None}
    return WorldSpec.model_validate({**spec.model_dump(), **update}) if update else spec


def _locate(alias: str, ref: DatabaseRef, world: SweptWorld) -> tuple[str, Generation | None]:
    """Database ``alias`` in ``world``: its locator (see :class:`Source`) and the generation it
    needs (its own world, or its generated set's, swept); None for a real set."""
    if ref.world is not None:
        generation = Generation(_in_world(ref.world, world), name=alias)
        return str(generation.folder), generation
    assert ref.name is not None
    manifest, own_folder = catalog.find_manifest(ref.name, ref.overrides)
    generator = manifest.generator
    if generator is None:
        return ref.name, None
    swept = _in_world(generator.spec, world)
    if swept != generator.spec:
        generation = Generation(swept, name=manifest.name)
        return str(generation.folder), generation
    folder = catalog.generated_location(manifest, own_folder, None)
    return ref.name, Generation(swept, folder, manifest.name, manifest.description)


def _prepare(
    alias: str, ref: DatabaseRef, config: RunConfig, locator: str, generated: bool
) -> Source:
    """The source of database ``alias`` at ``locator`` (``generated``: a generated world,
    finished by now)."""
    path = ref.path
    database = catalog.resolve(locator, None if generated else path, ref.overrides)
    manifest = database.manifest
    kinds = _kinds_read(config, alias, database_label(manifest.name, ref.name or alias), manifest)
    database.check_images(kinds)
    generator = manifest.generator
    if generator is not None:
        identity = database_key = f"{manifest.name}-{generator.spec.key()}"
    else:
        identity = f"{manifest.name}-{real_identity(database)}"
        database_key = f"{manifest.name}-{content_key(database, kinds)}"
    needs_unfold = "unfolded" not in manifest.kinds
    return Source(
        alias=alias,
        identity=identity,
        database_key=database_key,
        locator=locator,
        path=path,
        grid=database.grid,
        unfold_geometry=config.unfold.geometry() if needs_unfold else None,
        seed=generator.spec.seed if generator is not None else None,
        style=generator.spec.style if generator is not None else None,
        overrides=ref.overrides,
    )


def real_identity(database: GridDatabase) -> str:
    """12 hex digits naming a real set as a run reads it: its folder and what its manifest says
    of the images (grid, headings, camera models; a BoB folder's as its homebench.yaml and the
    config's ``images:`` state them; posed places' positions, the positions a grid misses), so
    that correcting a pose or a camera model recomputes what was computed with the old one."""
    manifest = database.manifest.model_dump(mode="json", exclude={"name", "description"})
    grid = database.grid  # posed places' positions and a grid's holes: not in the manifest
    extra = grid.xy if isinstance(grid, Places) else missing_positions(grid)
    return stable_hash([str(database.root.resolve()), manifest, *extra], 12)


def content_key(database: GridDatabase, kinds: tuple[ImageKind, ...]) -> str:
    """16 hex digits naming what a real set's images of ``kinds`` hold (their sha256s, by
    position): two copies of a set in other folders have the same key, an edited image
    another. Files are hashed once (:func:`~homebench.data.file_hashes.file_hashes`)."""
    paths = {(kind, i, j): database.path(i, j, kind) for kind in kinds for i, j in
             database.grid.indices()}  # fmt: skip
    sums = file_hashes(paths.values())
    return stable_hash([(*position, sums[path]) for position, path in paths.items()], 16)


def _kinds_read(
    config: RunConfig, alias: str, label: str, manifest: Manifest
) -> tuple[ImageKind, ...]:
    """The image kinds the config's methods read from database ``alias`` (named ``label``):
    each method's own kind, or raw images to unfold where the database has no unfolded ones
    (see :func:`database_view`). ConfigError naming the method's label and the database if a
    method needs raw images and the database has only unfolded ones."""
    read = set()
    for label, method, _ in config.method_points():
        kind = registry.get(method).image_kind
        if kind not in manifest.kinds and not (kind == "unfolded" and "raw" in manifest.kinds):
            name = f" ({label})" if label != alias else ""
            raise ConfigError(
                f"methods: {label!r} ({method}) needs {kind} images, but database {alias!r}{name} "
                f"has only {' and '.join(manifest.kinds)} images"
            )
        read.add(kind if kind in manifest.kinds else "raw")
    return tuple(kind for kind in KINDS if kind in read)


def prepare_sources(
    config: RunConfig, jobs: int, on_generate: Callable[[], object] | None = None
) -> dict[tuple[str, SweptWorld], Source]:
    """Sources of every database alias used by a condition, per swept world (generating worlds
    as needed; ``on_generate()`` is called first when there are any). Keys: (alias, (style,
    seed)), each None when the config does not sweep it."""
    used = {alias for _, current, goal in config.condition_pairs() for alias in (current, goal)}
    located = {
        (alias, world): _locate(alias, ref, world)
        for world in config.worlds()
        for alias, ref in config.databases.items()
        if alias in used
    }
    generate_many([g for _, g in located.values() if g is not None], jobs, on_start=on_generate)
    return {
        (alias, world): _prepare(alias, config.databases[alias], config, locator, g is not None)
        for (alias, world), (locator, g) in located.items()
    }


@lru_cache(maxsize=32)
def open_source(source: Source) -> GridDatabase:
    """The database of a source, opened once per process."""
    return catalog.resolve(source.locator, source.path, source.overrides)


def database_view(
    database: GridDatabase,
    i: int,
    j: int,
    kind: ImageKind,
    unfold_geometry: PanoramaGeometry | None,
) -> View:
    """The (i, j) view of ``kind``; raw-only databases give unfolded views by unfolding to
    ``unfold_geometry``. A kind the database cannot give is a DataError."""
    if kind in database.kinds:
        return database.view(i, j, kind)
    if kind == "unfolded" and unfold_geometry is not None:
        return unfolded_view(database.view(i, j, "raw"), unfold_geometry)
    raise DataError(
        f"database {database.name!r} has no {kind!r} images (it has: {', '.join(database.kinds)})"
    )


def unfolded_view(raw: View, geometry: PanoramaGeometry) -> View:
    """The raw (catadioptric) ``raw`` view unfolded to a panorama of ``geometry``."""
    return View(unfold(raw.image, raw.geometry, geometry), geometry)


def load_view(source: Source, i: int, j: int, kind: ImageKind, rotation: float = 0.0) -> View:
    """The view of (i, j) a method of ``kind`` needs, turned by ``rotation`` (radians, ccw)."""
    view = database_view(open_source(source), i, j, kind, source.unfold_geometry)
    return rotate_view(view, rotation) if rotation else view
