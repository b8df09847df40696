"""Planning: a validated run config -> independent describe and home jobs with stable keys.

Two kinds of job:

- a **describe job** computes one method's features for a batch of images and writes one
  feature file per image, keyed by (method, its code version, parameters, database identity,
  position, rotation, image content); every home job that needs an image reuses it;
- a **home job** runs one method for one goal and all its current positions of one condition,
  and writes one result file keyed by a hash of everything that determines its rows.

Code versions come from :mod:`~homebench.evaluation.code_version`, image contents from
:mod:`~homebench.evaluation.image_hashes`: a changed method or image changes the keys of exactly
the jobs and features it touches. A home job's key also holds the content of every other view
it reads (its ``context``): the grid neighbours of methods that sample around the current view
(``uses_neighbours``), the route views of methods that track (``uses_route``), the unfolded
views the visual compass compares and the headings the true compass turns by (a real set's
poses and camera models are in its identity: :func:`~homebench.evaluation.sources.real_identity`). A
method entry's ``compass`` (:data:`~homebench.methods.image_difference.visual_compass.CompassMode`)
is part of
its key; with a compass the current views are described inside the home job (turned back per
pair), so describe jobs hold its goals only.

Jobs carry database *sources* (paths and identities), never image arrays, so they travel cheaply
to worker processes or a cluster.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from homebench.bounds import MAX_PAIRS, count_problem
from homebench.config import RunConfig, SweptWorld
from homebench.errors import ConfigError
from homebench.evaluation.code_version import code_version
from homebench.evaluation.grid_routes import method_route
from homebench.evaluation.image_hashes import image_hashes
from homebench.evaluation.sources import Source, open_source
from homebench.geometry import Grid, is_places, missing_positions
from homebench.hashing import derived_seed, stable_hash
from homebench.methods import registry
from homebench.views import ImageKind

Position = tuple[int, int]
#: A current view of a job: grid position and rotation (radians).
Current = tuple[int, int, float]

#: Images per describe job: large enough to amortise process hand-over, small enough to balance.
DESCRIBE_BATCH = 8


@dataclass(frozen=True)
class MethodSpec:
    """One method entry of the config: table label, registered name, the parameters it sets,
    the method's code version, and the entry's compass with the compass's code version ("" with
    ``compass = none``)."""

    label: str
    method: str
    params: tuple[tuple[str, Any], ...]
    code: str
    compass: str = "none"
    compass_code: str = ""

    @functools.cached_property  # hashed once: feature paths and keys ask for it per image
    def key(self) -> str:
        fields = {"method": self.method, "params": dict(self.params), "code": self.code}
        if self.compass != "none":  # keys without a compass stay those of earlier versions
            fields["compass"] = [self.compass, self.compass_code]
        return stable_hash(fields)

    @property
    def image_kind(self) -> ImageKind:
        return registry.get(self.method).image_kind

    def create(self) -> Any:
        return registry.create(self.method, **dict(self.params))


class ImageInputs(NamedTuple):
    """What determines an image as a method sees it (part of every key): database identity,
    grid position, rotation (radians, ccw) and content. A tuple of strings and numbers, so it
    hashes and compares at C speed, where an :class:`ImageTask` hashes its whole source."""

    identity: str
    i: int
    j: int
    rotation: float
    content: str

    def feature_key(self, method_key: str) -> str:
        """The key of this image's features by the method of key ``method_key``."""
        return stable_hash({"method": method_key, "image": self})

    def feature_path(self, run_dir: Path, method_key: str) -> Path:
        """The file of this image's features by the method of key ``method_key``."""
        rotation = f"_r{round(math.degrees(self.rotation) * 1000)}" if self.rotation else ""
        name = f"{self.i}_{self.j}{rotation}.npz"
        return run_dir / "features" / method_key / self.identity / name


@dataclass(frozen=True, eq=False)
class ImageTask:
    """One image as a method sees it: database, grid position, rotation (radians, ccw), and
    its content (see :func:`~homebench.evaluation.image_hashes.image_hashes`). Tasks are equal
    when their inputs are, and hash by them: the source's identity names its images, and a
    dataclass's own hash would walk the whole source (grid, geometry) on every call."""

    source: Source
    i: int
    j: int
    rotation: float = 0.0
    content: str = ""

    @property
    def inputs(self) -> ImageInputs:
        """What determines this image as the method sees it (part of every key)."""
        return ImageInputs(*self._inputs())

    def _inputs(self) -> tuple[str, int, int, float, str]:
        """The fields of :attr:`inputs` as a plain tuple: equal to it and of the same hash, and
        built in a fifth of the time (planning hashes every task several times)."""
        return (self.source.identity, self.i, self.j, self.rotation, self.content)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ImageTask) and self._inputs() == other._inputs()

    def __hash__(self) -> int:
        return hash(self._inputs())


@dataclass(frozen=True)
class DescribeJob:
    method: MethodSpec
    images: tuple[ImageTask, ...]

    @functools.cached_property
    def key(self) -> str:
        return stable_hash({"method": self.method.key, "images": [t.inputs for t in self.images]})


@dataclass(frozen=True)
class HomeJob:
    """One method, one goal, all current positions of one condition."""

    condition: str
    method: MethodSpec
    goal: ImageTask
    currents: tuple[ImageTask, ...]
    seed: int | None = None  # the swept world seed, None without a sweep
    style: str | None = None  # the swept world style, None without a sweep
    context: str = ""  # hash of the other views and headings the job reads ("" when none)

    @functools.cached_property  # hashes every current view: asked for many times per job
    def key(self) -> str:
        fields = {
            "style": self.style,
            "seed": self.seed,
            "condition": self.condition,
            "method": self.method.key,
            "goal": self.goal.inputs,
            "currents": [t.inputs for t in self.currents],
        }
        if self.context:
            fields["context"] = self.context
        return stable_hash(fields)

    def result_path(self, run_dir: Path) -> Path:
        return run_dir / "jobs" / f"{self.key}.json"


@dataclass(frozen=True)
class Plan:
    describe: tuple[DescribeJob, ...]
    home: tuple[HomeJob, ...]


def select_goals(config: RunConfig, grid: Grid, source: Path | str) -> list[tuple[int, int]]:
    """The goal positions of the config, checked against the grid (ConfigError naming the key).
    On posed places (:class:`~homebench.geometry.Places`) an explicit goal ``[k, 0]`` names
    image k, the k-th row of the database's listing (from 0)."""
    if config.goals == "all":
        return list(grid.indices())
    if isinstance(config.goals, list):
        for k, (i, j) in enumerate(config.goals):
            if not grid.contains(i, j):
                raise ConfigError(f"{source}: goals.{k}: ({i}, {j}) is outside {_layout(grid)}")
        return [tuple(g) for g in config.goals]
    positions = list(grid.indices())
    if config.goals.random > len(positions):
        raise ConfigError(
            f"{source}: goals.random: {config.goals.random} goals asked, "
            f"{_layout(grid)} has {len(positions)} positions"
        )
    rng = np.random.default_rng(config.goals.seed)
    chosen = rng.choice(len(positions), size=config.goals.random, replace=False)
    return [positions[k] for k in sorted(chosen)]


def _layout(grid: Grid) -> str:
    """The grid (or posed places) in words, for messages."""
    nx, ny = grid.shape
    if is_places(grid):
        return (
            f"the {nx} posed images (not a grid: a goal [k, 0] names image k, k = 0..{nx - 1}, "
            "in the order of the database's listing)"
        )
    missing = missing_positions(grid)
    if missing:
        return f"the {nx} x {ny} grid, {len(missing)} of whose positions have no image"
    return f"the {nx} x {ny} grid"


def select_currents(config: RunConfig, grid: Grid, goal: tuple[int, int]) -> list[tuple[int, int]]:
    """Current positions for a goal: all but the goal itself, within the distance range."""
    goal_xy = grid.position(*goal)
    low, high = (
        (0.0, math.inf)
        if config.currents == "all"
        else (
            config.currents.min_distance,
            config.currents.max_distance,
        )
    )
    indices = list(grid.indices())
    i, j = np.array(indices).T
    distances = np.hypot(*(grid.position(i, j) - goal_xy).T).tolist()  # (n,), metres
    return [
        index
        for index, distance in zip(indices, distances, strict=True)
        if index != goal and low - 1e-9 <= distance <= high + 1e-9
    ]


def rotation_of(config: RunConfig, source: Source, i: int, j: int) -> float:
    """The seeded whole-column rotation (radians) of a current view, or 0 when disabled."""
    if not config.rotate_current.enabled:
        return 0.0
    rng = np.random.default_rng(derived_seed(config.rotate_current.seed, source.identity, i, j))
    columns = source.columns
    return 2.0 * math.pi * int(rng.integers(columns)) / columns


def method_specs(config: RunConfig) -> list[MethodSpec]:
    """The method points of a config with their code versions. Parameters are the config's:
    a default is part of the method's source, so its code version covers it."""
    names = {name for _, name, _ in config.method_points()} | {COMPASS_METHOD}
    versions = {name: code_version(registry.get(name)) for name in names}
    specs = []
    for entry in config.methods:
        compass_code = versions[COMPASS_METHOD] if entry.compass != "none" else ""
        for label, params in entry.expand():
            method = (label, entry.method, tuple(sorted(params.items())), versions[entry.method])
            specs.append(MethodSpec(*method, entry.compass, compass_code))
    return specs


#: The registered method whose module holds the engine's compass step (its code version keys
#: every job with a compass).
COMPASS_METHOD = "visual-compass"


def neighbour_positions(grid: Grid, i: int, j: int, step: int) -> list[tuple[int, int]]:
    """Grid positions ``step`` units from (i, j) along each grid axis (+i, -i, +j, -j), those
    inside the grid."""
    found = [(i + step, j), (i - step, j), (i, j + step), (i, j - step)]
    return [(a, b) for a, b in found if grid.contains(a, b)]


def extra_positions(
    method: Any, grid: Grid, goal: tuple[int, int], current: tuple[int, int]
) -> list[tuple[int, int]]:
    """Grid positions of the views a method reads for one pair beyond its two (from the
    current database): the route from the goal (``uses_route``, see
    :func:`~homebench.evaluation.grid_routes.method_route`), then the current view's
    neighbours (``uses_neighbours``, its ``neighbour_step``)."""
    found = method_route(method, grid, goal, current)
    if getattr(method, "uses_neighbours", False):
        found += neighbour_positions(grid, *current, int(getattr(method, "neighbour_step", 1)))
    return found


def described(job: HomeJob) -> tuple[ImageTask, ...]:
    """The images of a home job its describe jobs describe: the goal, and the current views
    unless a compass turns them back per pair inside the home job."""
    return (job.goal,) if job.method.compass != "none" else (job.goal, *job.currents)


def check_places(
    source: Source, methods: list[MethodSpec], instances: dict[str, Any], config_path: Path | str
) -> None:
    """ConfigError naming the first method that reads grid neighbours (``uses_neighbours``) or
    views along grid routes (``uses_route`` with a ``route_step`` above 0) when ``source``
    holds posed places, which have neither."""
    if not is_places(source.grid):
        return
    for method in methods:
        instance = instances[method.label]
        if getattr(instance, "uses_neighbours", False):
            reads, remedy = "the grid neighbours of each current view", "leave the method out"
        elif getattr(instance, "uses_route", False) and getattr(instance, "route_step", 0) > 0:
            reads, remedy = "views along grid routes", "set its route_step to 0, or leave it out"
        else:
            continue
        raise ConfigError(
            f"{config_path}: methods: {method.label!r} ({method.method}) reads {reads}, but "
            f"database {source.alias!r} holds posed images, not a grid: {remedy}"
        )


def check_size(
    config: RunConfig, sources: dict[tuple[str, SweptWorld], Source], config_path: Path | str
) -> None:
    """ConfigError when the run's jobs, or its pairs (at most every other grid position per
    goal), are more than one run can hold; asked before any job is planned."""
    methods = sum(entry.n_points for entry in config.methods)
    goals = pairs = 0
    for world in config.worlds():
        for _, current_alias, goal_alias in config.condition_pairs():
            grid = sources[goal_alias, world].grid
            n = len(select_goals(config, grid, config_path))
            goals += n
            pairs += n * (sources[current_alias, world].grid.size - 1)
    counts = {"goals": goals, "methods": methods}
    problem = count_problem(counts, "jobs") or count_problem(
        counts, "pairs", MAX_PAIRS, total=pairs * methods
    )
    if problem:
        raise ConfigError(f"{config_path}: {problem}")


def make_plan(
    config: RunConfig, sources: dict[tuple[str, SweptWorld], Source], config_path: Path | str
) -> Plan:
    """All jobs of a run, in a deterministic order; ConfigError when it would be more than one
    run can hold (:func:`check_size`)."""
    check_size(config, sources, config_path)
    methods = method_specs(config)
    instances = {method.label: method.create() for method in methods}
    contents: dict[tuple[str, ImageKind], dict[tuple[int, int], str]] = {}

    def content(source: Source, kind: ImageKind, i: int, j: int) -> str:
        if (source.identity, kind) not in contents:
            contents[source.identity, kind] = image_hashes(source, kind, source.grid.indices())
        return contents[source.identity, kind][i, j]

    def task(source: Source, i: int, j: int, kind: ImageKind, rotation: float = 0.0) -> ImageTask:
        return ImageTask(source, i, j, rotation, content(source, kind, i, j))

    def context(
        method: MethodSpec,
        current_src: Source,
        goal_src: Source,
        goal: Position,
        currents: list[Current],
    ) -> str:
        """Hash of what the job reads beyond its tasks' images ("" when nothing)."""
        here = [(i, j) for i, j, _ in currents]
        grid, kind = current_src.grid, method.image_kind
        extra = {p for c in here for p in extra_positions(instances[method.label], grid, goal, c)}
        parts: list[Any] = [("view", *p, content(current_src, kind, *p)) for p in sorted(extra)]
        read = [(goal_src, goal), *((current_src, c) for c in here)]
        if method.compass == "visual" and kind != "unfolded":
            parts += [("compass", s.identity, *p, content(s, "unfolded", *p)) for s, p in read]
        if method.compass == "truth":
            parts += [("heading", s.identity, *p, open_source(s).heading(*p)) for s, p in read]
        return stable_hash(parts) if parts else ""

    home: list[HomeJob] = []
    for world in config.worlds():
        for condition, current_alias, goal_alias in config.condition_pairs():
            current_src, goal_src = sources[current_alias, world], sources[goal_alias, world]
            if current_src.grid != goal_src.grid:
                what = (
                    "places" if is_places(current_src.grid) or is_places(goal_src.grid) else "grids"
                )
                raise ConfigError(
                    f"{config_path}: conditions: {condition!r} pairs databases with different "
                    f"{what} ({current_src.grid} vs {goal_src.grid})"
                )
            check_places(current_src, methods, instances, config_path)
            for goal in select_goals(config, goal_src.grid, config_path):
                currents = [
                    (i, j, rotation_of(config, current_src, i, j))
                    for i, j in select_currents(config, current_src.grid, goal)
                ]
                for method in methods:
                    kind = method.image_kind
                    tasks = tuple(task(current_src, i, j, kind, r) for i, j, r in currents)
                    goal_task = task(goal_src, *goal, kind)
                    style, seed = world
                    reads = context(method, current_src, goal_src, goal, currents)
                    home.append(HomeJob(condition, method, goal_task, tasks, seed, style, reads))
    describe = []
    for method in {m.key: m for m in methods}.values():  # equal parameters share features
        needed = sorted(
            {t for job in home if job.method.key == method.key for t in described(job)},
            key=lambda t: t.inputs,
        )
        for start in range(0, len(needed), DESCRIBE_BATCH):
            describe.append(DescribeJob(method, tuple(needed[start : start + DESCRIBE_BATCH])))
    return Plan(tuple(describe), tuple(home))
