"""Generate a grid database from a world spec, reproducibly and never half-written.

A generated folder holds ``raw/X_Y.png``, ``unfolded/X_Y.png``, ``ground_truth.json`` and
``manifest.yaml`` (the spec, its key and every file's sha256). It is built in a temporary sibling
folder and renamed into place at the end; the output bytes depend on the spec only, not on the
number of jobs.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import warnings
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.bounds import workers_problem
from homebench.data.fingerprint import fingerprint
from homebench.data.manifest import (
    SCHEMA_VERSION,
    CatadioptricSection,
    Generator,
    GridSection,
    ImagesSection,
    Manifest,
    PanoramaSection,
    RawImages,
    UnfoldedImages,
    load_manifest,
)
from homebench.data.progress import bar
from homebench.data.synth.spec import RENDERER_VERSION, WorldSpec
from homebench.errors import ConfigError, DataError
from homebench.fileio import atomic_directory, encode_png, write_bytes_atomic, write_text_atomic
from homebench.geometry import grid_key

MANIFEST_NAME = "manifest.yaml"
GROUND_TRUTH_NAME = "ground_truth.json"
IMAGE_PATTERN = "{x}_{y}.png"
#: Tasks per worker: enough for load balancing, few enough that each worker builds the world once.
BATCHES_PER_JOB = 4

Progress = Callable[[int, int], None]


class Renderer(Protocol):
    """What generation needs from a renderer (the real one is homebench.data.synth.world)."""

    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, NDArray[np.uint8]]:
        """Images of grid position (i, j): {"raw": (h, w) uint8, "unfolded": (h, w) uint8}."""
        ...

    def ground_truth(self, spec: WorldSpec) -> dict[str, Any]:
        """The world's ground truth, JSON-serialisable."""
        ...


class SynthRenderer:
    """The built-in ray-cast renderer (imported on first use: it builds textures)."""

    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, NDArray[np.uint8]]:
        from homebench.data.synth.world import render_position

        return render_position(spec, i, j)

    def ground_truth(self, spec: WorldSpec) -> dict[str, Any]:
        from homebench.data.synth.world import build_world

        return build_world(spec).ground_truth()


def data_dir() -> Path:
    """Where homebench keeps data: ``$HOMEBENCH_DATA`` or ``~/.cache/homebench``."""
    env = os.environ.get("HOMEBENCH_DATA")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "homebench"


def generated_root(name: str, spec: WorldSpec) -> Path:
    """Cache folder of a generated set: ``<data dir>/synth/<name>-<spec key>``."""
    return data_dir() / "synth" / f"{name}-{spec.key()}"


def manifest_for_spec(
    spec: WorldSpec,
    name: str,
    description: str = "",
    files: dict[str, dict[str, str | None]] | None = None,
    fingerprints: dict[str, dict[str, str]] | None = None,
) -> Manifest:
    """The manifest of a generated set: grid, heading and cameras from ``spec``.

    ``files`` maps kind -> file name -> sha256 (or None), ``fingerprints`` kind -> file name ->
    content fingerprint; omitted kinds list no files.
    """
    files, fingerprints = files or {}, fingerprints or {}
    g = spec.to_grid()
    raw, unfolded = spec.raw.geometry(), spec.unfolded.geometry()
    return Manifest(
        schema=SCHEMA_VERSION,
        name=name,
        description=description or f"Generated world: variant {spec.variant}, seed {spec.seed}.",
        grid=GridSection(shape=g.shape, spacing=g.spacing, origin=_rounded(g.origin)),
        heading_deg=spec.heading_deg,
        images=ImagesSection(
            raw=RawImages(
                folder="raw",
                pattern=IMAGE_PATTERN,
                extensions=("png",),
                size=(raw.width, raw.height),
                catadioptric=CatadioptricSection.from_geometry(raw),
                files=files.get("raw", {}),
                fingerprints=fingerprints.get("raw", {}),
            ),
            unfolded=UnfoldedImages(
                folder="unfolded",
                pattern=IMAGE_PATTERN,
                extensions=("png",),
                size=(unfolded.width, unfolded.height),
                panorama=PanoramaSection.from_geometry(unfolded),
                files=files.get("unfolded", {}),
                fingerprints=fingerprints.get("unfolded", {}),
            ),
        ),
        generator=Generator(spec=spec, key=spec.key()),
        ground_truth=GROUND_TRUTH_NAME,
    )


def _rounded(values: tuple[float, ...]) -> tuple[float, ...]:
    """Values rounded to 1e-9 (no 1.6500000000000001 in a manifest; the check allows 1e-9)."""
    return tuple(round(v, 9) for v in values)


def is_generated(folder: Path, spec: WorldSpec) -> bool:
    """True if ``folder`` holds a finished generation of ``spec`` (manifest with its key)."""
    path = Path(folder) / MANIFEST_NAME
    if not path.is_file():
        return False
    try:
        manifest = load_manifest(path)
    except ConfigError:
        return False
    return manifest.generator is not None and manifest.generator.key == spec.key()


@dataclass(frozen=True)
class Generation:
    """A world to generate: its ``spec``, its folder ``out_dir`` (None: :func:`generated_root`
    of ``name``), its set's ``name`` and ``description``."""

    spec: WorldSpec
    out_dir: Path | None = None
    name: str = "synth"
    description: str = ""

    @property
    def folder(self) -> Path:
        """Where the generation goes."""
        if self.out_dir is not None:
            return Path(self.out_dir)
        return generated_root(self.name, self.spec)


def generate(
    spec: WorldSpec,
    out_dir: Path | None = None,
    jobs: int = 1,
    name: str = "synth",
    *,
    description: str = "",
    renderer: Renderer | None = None,
    progress: Progress | None = None,
) -> Path:
    """Render every grid position of ``spec`` in both kinds into a new folder; return it.

    ``out_dir`` defaults to :func:`generated_root`. A folder that already holds this spec's
    generation is returned as it is; any other existing folder but an empty one is a DataError
    (never overwritten). ``jobs`` follows joblib (-1 = all cores); ``progress(done, total)``
    is called as positions finish, and a bar shows them (:mod:`homebench.data.progress`).
    """
    generation = Generation(spec, out_dir, name, description)
    (folder,) = generate_many([generation], jobs, renderer=renderer, progress=progress)
    return folder


def generate_many(
    generations: Sequence[Generation],
    jobs: int = 1,
    *,
    renderer: Renderer | None = None,
    progress: Progress | None = None,
    on_start: Callable[[], object] | None = None,
) -> list[Path]:
    """Generate each of ``generations`` as :func:`generate` does; their folders, in order.

    The positions of every world that is not generated yet are rendered by one pool of ``jobs``
    workers, so that no world waits for the last positions of the one before it; each world's
    ground truth is a task of the pool too. ``progress(done, total)`` counts all positions;
    ``on_start()`` is called before rendering begins (never when no world is to be rendered).
    ConfigError when ``jobs`` is no number of workers.
    """
    problem = workers_problem(jobs)
    if problem:
        raise ConfigError(problem)
    pending = _pending(generations)
    if pending:
        if on_start is not None:
            on_start()
        try:
            _generate_pending(pending, jobs, renderer or SynthRenderer(), progress)
        except DataError:
            if not all(is_generated(g.folder, g.spec) for g in pending):
                raise  # else another process finished the same worlds first
    return [generation.folder for generation in generations]


def _pending(generations: Sequence[Generation]) -> list[Generation]:
    """The generations whose folders do not hold them yet, once each; DataError for a folder
    that holds something else, or that two different specs would share."""
    pending: dict[Path, Generation] = {}
    for generation in generations:
        folder, spec = generation.folder, generation.spec
        if folder in pending and pending[folder].spec != spec:
            raise DataError(f"{folder}: two different worlds ({pending[folder].spec.key()} and "
                            f"{spec.key()}) would be generated into the same folder")  # fmt: skip
        if folder in pending or is_generated(folder, spec):
            continue
        if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
            raise DataError(
                f"{folder}: exists but is not a finished generation of spec {spec.key()}; "
                "remove it or choose another folder"
            )
        pending[folder] = generation
    return list(pending.values())


def _generate_pending(
    pending: list[Generation], jobs: int, renderer: Renderer, progress: Progress | None
) -> None:
    """Build every generation of ``pending`` in a temporary folder
    (:func:`~homebench.fileio.atomic_directory`), then move each into place; a failure leaves
    none of the unfinished ones behind."""
    stacks = [ExitStack() for _ in pending]  # one each: a world's move fails it alone
    with ExitStack() as on_failure:  # exits every world's stack with the error: no move
        folders = []
        for stack, generation in zip(stacks, pending, strict=True):
            on_failure.push(stack)
            folders.append(stack.enter_context(atomic_directory(generation.folder)))
        _build(list(zip(pending, folders, strict=True)), jobs, renderer, progress)
        on_failure.pop_all()  # built: the worlds move in below, each on its own
    failed = []
    for stack in stacks:  # each moves its folder into place
        try:
            stack.close()
        except DataError as error:  # the folder appeared meanwhile: the caller looks at it
            failed.append(error)
    if failed:
        raise failed[0]


def _build(
    staged: list[tuple[Generation, Path]],
    jobs: int,
    renderer: Renderer,
    progress: Progress | None,
) -> None:
    """Fill each staged folder with images, ground truth and, last, the manifest: one task per
    batch of positions, then each world's ground truth, in one parallel pass."""
    from joblib import Parallel, delayed, effective_n_jobs  # here: job workers never need it

    n_jobs = effective_n_jobs(jobs)
    tasks: list[tuple[int, list[tuple[int, int]]]] = []  # (staged index, positions; [] = truth)
    for index, (generation, folder) in enumerate(staged):
        for kind in ("raw", "unfolded"):
            (folder / kind).mkdir()
        positions = list(generation.spec.to_grid().indices())
        # in this process, one position per batch costs nothing and moves the bar by positions
        batches = _split(positions, n_jobs * BATCHES_PER_JOB if n_jobs > 1 else len(positions))
        tasks += [(index, batch) for batch in batches] + [(index, [])]
    written: list[list[tuple[str, str, str, str]]] = [[] for _ in staged]
    truths: list[dict[str, Any]] = [{} for _ in staged]
    total, done = sum(len(batch) for _, batch in tasks), 0
    names = ", ".join(generation.name for generation, _ in staged)
    with bar(total, f"generate {names}", "position", log=True) as shown, warnings.catch_warnings():
        # loky replaces a worker whose memory grew (a world's textures: ~250 MB) and says so
        warnings.filterwarnings("ignore", "A worker stopped while some jobs", UserWarning)
        results = Parallel(n_jobs=n_jobs, return_as="generator")(
            delayed(_run_task)(renderer, *staged[index], batch, n_jobs > 1)
            for index, batch in tasks
        )
        for (index, batch), result in zip(tasks, results, strict=True):
            if not batch:
                truths[index] = result
                continue
            written[index] += result
            done += len(batch)
            shown.update(len(batch))
            if progress is not None:
                progress(done, total)
    for (generation, folder), files, truth in zip(staged, written, truths, strict=True):
        _finish(generation, folder, files, truth)


def _finish(
    generation: Generation,
    folder: Path,
    written: list[tuple[str, str, str, str]],
    truth: dict[str, Any],
) -> None:
    """Write the ground truth and, last, the manifest of a generation's ``written`` files
    (kind, file name, sha256, fingerprint)."""
    files: dict[str, dict[str, str | None]] = {"raw": {}, "unfolded": {}}
    prints: dict[str, dict[str, str]] = {"raw": {}, "unfolded": {}}
    for kind, file_name, digest, content in sorted(written):
        files[kind][file_name] = digest
        prints[kind][file_name] = content
    write_text_atomic(folder / GROUND_TRUTH_NAME, json.dumps(truth, indent=1, sort_keys=True))
    spec, name, description = generation.spec, generation.name, generation.description
    manifest = manifest_for_spec(spec, name, description, files, prints)
    write_text_atomic(folder / MANIFEST_NAME, manifest.to_yaml())


def _run_task(
    renderer: Renderer,
    generation: Generation,
    folder: Path,
    positions: list[tuple[int, int]],
    in_worker: bool,
) -> Any:
    """A batch of positions (:func:`_render_batch`), or with none the world's ground truth."""
    if not positions:
        return _ground_truth(generation.spec, renderer)
    return _render_batch(renderer, generation.spec, folder, positions, in_worker)


def _split(items: Sequence[tuple[int, int]], n: int) -> list[list[tuple[int, int]]]:
    """``items`` in at most ``n`` contiguous batches of nearly equal size."""
    size = math.ceil(len(items) / max(1, n))
    return [list(items[k : k + size]) for k in range(0, len(items), size)]


def _render_batch(
    renderer: Renderer,
    spec: WorldSpec,
    folder: Path,
    positions: list[tuple[int, int]],
    in_worker: bool,
) -> list[tuple[str, str, str, str]]:
    """Render and write ``positions``; return (kind, file name, sha256, fingerprint) per file
    written."""
    if in_worker:
        cv2.setNumThreads(1)  # the workers already use every core
    expected = {
        "raw": (spec.raw.height, spec.raw.width),
        "unfolded": (spec.unfolded.height, spec.unfolded.width),
    }
    written = []
    for i, j in positions:
        images = renderer.render_position(spec, i, j)
        for kind, shape in expected.items():
            image = images[kind]
            if image.dtype != np.uint8 or image.shape != shape:
                raise DataError(
                    f"renderer returned a {kind} image of shape {image.shape} {image.dtype} "
                    f"at ({i},{j}), expected {shape} uint8"
                )
            data = encode_png(image)
            file_name = IMAGE_PATTERN.format(x=i, y=j)
            write_bytes_atomic(folder / kind / file_name, data)
            digest = hashlib.sha256(data).hexdigest()
            written.append((kind, file_name, digest, fingerprint(image)))
    return written


def _ground_truth(spec: WorldSpec, renderer: Renderer) -> dict[str, Any]:
    """Camera pose of every grid position plus the world's own ground truth."""
    poses = {}
    for i, j in spec.to_grid().indices():
        pose = spec.pose(i, j)
        poses[grid_key(i, j)] = {"x": pose.x, "y": pose.y, "heading": pose.heading}
    return {
        "spec_key": spec.key(),
        "renderer_version": RENDERER_VERSION,
        "camera_height": spec.camera_height,
        "poses": poses,
        "world": renderer.ground_truth(spec),
    }
