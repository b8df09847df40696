"""The run config: YAML -> validated, frozen objects. Unknown keys are errors ("did you mean").

Example (see ``configs/quickstart.yaml``)::

    name: quickstart
    output: runs/quickstart            # relative to the current directory
    databases:                         # alias -> a database
      original: synth-original         #   a known database name or a manifest path
      ants: data/ant_grid              #   a Brains on Board folder (database_entries.csv)
      day: {world: {variant: day, grid: {shape: [5, 7]}}}   # an inline generated world
    conditions: [original-original, original-day]   # current views from the first, goals
                                                    # from the second
    goals: [[2, 3]]                    # or "all", or {random: 5, seed: 1}
    currents: all                      # or {min_distance: 0.3, max_distance: 1.2} (metres)
    methods:
      - {method: warping}
      - {method: warping, label: warping-coarse, params: {n_rho: 10}}
      - {method: alv, label: alv-vc, compass: visual}   # current view turned back by the
                                                        # visual compass (or truth / none)

Checks that need the databases (a goal outside the grid) happen when the run is planned.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, field_validator, model_validator

from homebench.bounds import MAX_AHC_BINS, MAX_BANDS, count_problem, workers_problem
from homebench.claim_spec import ClaimEntry, RecordedClaim, claim_problem
from homebench.data.bob.overrides import (
    BobOverrides,
    GridOverride,
    HeadingsOverride,
    ImageOverrides,
    MissingPoses,
)
from homebench.data.synth.spec import Style, WorldSpec
from homebench.errors import ConfigError, HomebenchError
from homebench.geometry import PanoramaGeometry
from homebench.image_header import size_problem
from homebench.methods import registry
from homebench.methods.base import gives_direction
from homebench.methods.image_difference.visual_compass import CompassMode
from homebench.methods.param_types import parameter_problem
from homebench.strict import StrictModel
from homebench.suggest import did_you_mean
from homebench.yamlio import YamlDocument, read_yaml, validate

ALIAS = re.compile(r"^[A-Za-z0-9_]+$")
#: Largest seed a sweep takes: the tables' ``seed`` column holds 64-bit integers.
MAX_SWEPT_SEED = 2**63 - 1
#: A swept world: (style, seed), each None when not swept.
SweptWorld = tuple[str | None, int | None]
#: A job (or trial) running longer than this many seconds fails; None: never. Every kind of
#: config takes it as ``job_timeout_s`` (``homebench run --timeout`` overrides it).
JobTimeout = Annotated[float, Field(gt=0)] | None
DEFAULT_JOB_TIMEOUT_S = 3600.0


#: The keys of a database entry that state a Brains on Board folder's conventions.
_BOB_KEYS = ("images", "headings", "grid", "missing_poses")


class DatabaseRef(StrictModel):
    """A database of the run: a known name, manifest path or Brains on Board folder (``name``),
    or an inline ``world``. ``images`` (the camera model), ``headings`` (how headings are
    written), ``grid`` (the labels' order) and ``missing_poses`` (rows without a pose) state a
    Brains on Board folder's conventions, as its ``homebench.yaml`` would
    (:mod:`homebench.data.bob.overrides`), replacing the file's and what is assumed."""

    name: str | None = None  # a known database name, a manifest path or a BoB folder
    path: Path | None = None  # root of a real set's copy (overrides the manifest's env variable)
    world: WorldSpec | None = None  # an inline generated world (instead of name)
    images: ImageOverrides | None = None  # a BoB folder's camera model (raw or unfolded)
    # how a BoB folder's Heading [degrees] is written (default: compass bearings, 0 = +y, cw)
    headings: HeadingsOverride | None = None
    grid: GridOverride | None = None  # the order of a BoB grid's labels (Grid X, Grid Y)
    # a BoB folder's rows without X, Y or Heading: skip (default) or interpolate them
    missing_poses: MissingPoses | None = None

    @model_validator(mode="after")
    def _one_source(self) -> DatabaseRef:
        if (self.name is None) == (self.world is None):
            raise ValueError("give exactly one of 'name' and 'world'")
        if self.world is not None and self.path is not None:
            raise ValueError("'path' is for named databases, not generated worlds")
        for key in _BOB_KEYS:
            if self.world is not None and getattr(self, key) is not None:
                raise ValueError(f"{key!r} is for Brains on Board folders, not generated worlds")
        return self

    @property
    def overrides(self) -> BobOverrides | None:
        """What the entry states of a Brains on Board folder (None: nothing)."""
        stated = {k: getattr(self, k) for k in _BOB_KEYS}
        given = {k: v for k, v in stated.items() if v is not None}
        return BobOverrides(**given) if given else None


class RandomGoals(StrictModel):
    """Goals drawn at random from a database's grid positions."""

    random: int = Field(ge=1)  # how many goals, drawn without replacement
    seed: int = Field(0, ge=0)  # seed of the draw


class CurrentRange(StrictModel):
    """Current positions whose distance to the goal lies in [min_distance, max_distance] metres."""

    min_distance: float = Field(0.0, ge=0)  # metres from the goal, inclusive
    max_distance: float = Field(float("inf"), gt=0)  # metres from the goal, inclusive

    @model_validator(mode="after")
    def _ordered(self) -> CurrentRange:
        if self.max_distance < self.min_distance:
            raise ValueError("max_distance must not be below min_distance")
        return self


class MethodEntry(StrictModel):
    """A method with parameters; ``grid`` sweeps parameters (every combination of its lists);
    ``compass`` aligns the current view with the goal's before any method sees it (engine
    level: :data:`homebench.methods.image_difference.visual_compass.CompassMode`)."""

    method: str  # a registered method's name (`homebench methods` lists them)
    label: str | None = None  # its name in tables and reports; default: the method's name
    params: dict[str, Any] = Field(default_factory=dict)  # parameter -> value (see Methods)
    # parameter -> list of values: one entry per combination, labelled label[name=value,...]
    grid: dict[str, list[Any]] = Field(default_factory=dict)
    # none: views as taken; visual: the current view turned back by the visual compass's
    # RIDF minimum against the goal's; truth: turned back by the true heading change
    compass: CompassMode = "none"

    @field_validator("grid")
    @classmethod
    def _grid_lists(cls, value: dict[str, list[Any]]) -> dict[str, list[Any]]:
        empty = [name for name, values in value.items() if not values]
        if empty:
            raise ValueError(f"grid: {empty[0]!r} needs at least one value")
        problem = count_problem({name: len(values) for name, values in value.items()}, "points")
        if problem:
            raise ValueError(problem)
        return value

    @property
    def n_points(self) -> int:
        """How many (label, params) points :meth:`expand` gives."""
        return math.prod(len(values) for values in self.grid.values())

    @property
    def name(self) -> str:
        """The label shown in tables: ``label`` or the method name."""
        return self.label or self.method

    def expand(self) -> list[tuple[str, dict[str, Any]]]:
        """(label, params) of every grid point; labels name the swept values, e.g.
        ``sift[ratio=0.7]``. Without a grid: the entry itself."""
        if not self.grid:
            return [(self.name, dict(self.params))]
        names = sorted(self.grid)
        points = []
        for values in itertools.product(*(self.grid[n] for n in names)):
            swept = dict(zip(names, values, strict=True))
            tag = ",".join(f"{n}={v}" for n, v in swept.items())
            points.append((f"{self.name}[{tag}]", {**self.params, **swept}))
        return points


#: How a return-ratio walk ends on a grid position without an estimate: ``fail`` (the default;
#: seed 001's step procedure presumes an estimate everywhere and is silent on this:
#: :mod:`homebench.analysis.return_ratio` quotes it) or ``arrived``: a success when that
#: position is one of the goal's 8 grid neighbours (|di| <= 1 and |dj| <= 1), where warping-like
#: methods abstain when no shift beats rho = 0 (the view looks like home); a failure anywhere
#: else, so a method that abstains everywhere scores only the goal's and its neighbours' starts.
RRNoEstimate = Literal["fail", "arrived"]


class ReturnRatioConfig(StrictModel):
    """Seed 001's return ratio: step ``rh``, ``success_radius`` and ``max_travel`` in grid units
    (multiples of the grid spacing), and how a walk ends on a position without an estimate
    (``no_estimate``, :data:`RRNoEstimate`)."""

    rh: float = Field(0.8, gt=0)  # step length of a walk, grid units (seed 001: 0.8)
    # a walk succeeds within this many grid units of the goal (seed 001: 0.5)
    success_radius: float = Field(0.5, gt=0)
    max_travel: float | None = Field(None, gt=0)  # grid units; None: half the grid's perimeter
    # a walk on a position without an estimate: fail, or arrived when next to the goal
    no_estimate: RRNoEstimate = "fail"


#: The two AHCs of the literature: seed 001's eq. 12, the cosine of the mean AE
#: (``cos_mean_ae``), and the mean of the cosines, the mean homeward component of a unit home
#: vector (``mean_cos``), which Vardy & Möller (2005) and Möller & Vardy (2006) report.
AhcDefinition = Literal["cos_mean_ae", "mean_cos"]


class AhcConfig(StrictModel):
    """The AHC: its distance bins (cm), how a pair without an estimate enters it (``exclude``:
    left out, the paper's reading; ``orthogonal``: as 90 deg) and its ``definition``: seed
    001's eq. 12, ``cos_mean_ae`` (the cosine of the mean AE), or ``mean_cos`` (the mean of the
    cosines, as Vardy & Möller and Möller & Vardy report it)."""

    bin_start_cm: float = Field(30.0, gt=0)  # centre of the first distance bin, cm
    bin_stop_cm: float = Field(390.0, gt=0)  # centre of the last distance bin, cm
    bin_step_cm: float = Field(30.0, gt=0)  # width of a distance bin, cm
    # a pair without an estimate: exclude (left out, the paper's reading) or orthogonal (90 deg)
    missing: Literal["exclude", "orthogonal"] = "exclude"
    # cos_mean_ae: seed 001's eq. 12; mean_cos: the mean of the cosines (Vardy & Möller)
    definition: AhcDefinition = "cos_mean_ae"

    @model_validator(mode="after")
    def _bins(self) -> AhcConfig:
        # as many bins as np.arange(start, stop + step / 2, step) has (evaluation.results)
        span = (self.bin_stop_cm + self.bin_step_cm / 2 - self.bin_start_cm) / self.bin_step_cm
        if not 2 <= math.ceil(span) <= MAX_AHC_BINS:
            raise ValueError(
                f"bin_start_cm, bin_stop_cm and bin_step_cm make {max(0, math.ceil(span)):,} "
                f"distance bins; give 2 to {MAX_AHC_BINS:,}"
            )
        return self


class MetricsConfig(StrictModel):
    """The metrics: the AHC's, the return ratio's, Möller's catchment, and the edges of the
    distance bands (m, increasing) the band table reports the headline metrics in (the
    defaults: near, below 1.2 m; mid, to 2.4 m; far, beyond), so that one mean does not blend
    a method that works near the goal with one that fails far from it."""

    ahc: AhcConfig = AhcConfig()  # the AHC's distance bins, missing pairs and definition
    return_ratio: ReturnRatioConfig = ReturnRatioConfig()  # seed 001's return-ratio walks
    catchment: bool = True  # compute Möller's catchment area per goal
    # edges of the distance bands, metres, increasing (near < 1.2 m, mid to 2.4 m, far beyond)
    band_edges_m: tuple[float, ...] = (1.2, 2.4)

    @field_validator("band_edges_m")
    @classmethod
    def _edges(cls, edges: tuple[float, ...]) -> tuple[float, ...]:
        if not 1 <= len(edges) < MAX_BANDS:
            raise ValueError(f"give 1 to {MAX_BANDS - 1} band edges, got {len(edges)}")
        if edges[0] <= 0 or not all(a < b for a, b in itertools.pairwise(edges)):
            raise ValueError(f"band edges must be positive and increasing, got {list(edges)}")
        if not all(math.isfinite(e) for e in edges):
            raise ValueError("band edges must be finite")
        return edges


class RotationConfig(StrictModel):
    """Rotate every current view by a random whole number of columns (seeded)."""

    enabled: bool = False  # rotate the current views (off: views as taken)
    seed: int = Field(0, ge=0)  # seed of the rotations (drawn per database and position)


class UnfoldConfig(StrictModel):
    """Panorama made from raw images for methods that need unfolded views (raw-only databases)."""

    width: int = Field(288, ge=16)  # panorama columns (pixels; rows follow: square pixels)
    elevation_top_deg: float = Field(45.0, gt=0, lt=90)  # elevation of the top edge, degrees
    elevation_bottom_deg: float = Field(-50.0, gt=-90, lt=0)  # of the bottom edge, degrees

    @model_validator(mode="after")
    def _bounded(self) -> UnfoldConfig:
        problem = size_problem(self.width, self.geometry().height)
        if problem:
            raise ValueError(f"width {self.width}: {problem}")
        return self

    def geometry(self) -> PanoramaGeometry:
        return PanoramaGeometry.square_pixels(
            self.width,
            math.radians(self.elevation_top_deg),
            math.radians(self.elevation_bottom_deg),
        )


class Check(StrictModel):
    """Thresholds a method must meet for ``homebench run --check``, in every condition or in
    the ``conditions`` listed."""

    conditions: list[str] | None = None  # conditions checked; None: every condition

    ahc_min: float | None = Field(None, ge=-1, le=1)  # lowest AHC passed; None: unchecked
    rr_min: float | None = Field(None, ge=0, le=1)  # lowest return ratio passed
    mean_ae_max_deg: float | None = Field(None, ge=0, le=180)  # highest mean AE passed, degrees
    # highest share (0-1) of pairs without an estimate passed
    no_estimate_max: float | None = Field(None, ge=0, le=1)


class RunConfig(StrictModel):
    """A grid run (no ``kind``, or ``kind: grid``): every (goal, current) pair of its databases'
    grids, for each condition and method entry."""

    # A key's comment is its meaning in the documentation's config reference.

    name: str = "run"  # the run's name in tables and reports
    output: Path  # the run folder (relative to the current directory)
    # not read by a grid run (random goals, rotations and worlds take their own seeds)
    seed: int = Field(0, ge=0)
    jobs: int = 1  # parallel workers (-1: all cores; homebench run --jobs overrides it)
    job_timeout_s: JobTimeout = DEFAULT_JOB_TIMEOUT_S  # a job running longer fails; null: never
    # each worker's address-space limit; None: physical memory / (workers + 1)
    worker_memory_mb: int | None = Field(None, ge=1024)
    # alias -> a database: a known name, manifest path or Brains on Board folder, or a world
    databases: dict[str, DatabaseRef]
    # "current-goal" alias pairs (current views from the first, goals from the second); all
    conditions: list[str] | Literal["all"] = Field(min_length=1)
    seeds: list[int] = Field(default_factory=list)  # sweep the seed of every generated world
    styles: list[Style] = Field(default_factory=list)  # sweep the style of every generated world
    goals: list[tuple[int, int]] | Literal["all"] | RandomGoals  # grid indices (i, j) of goals
    currents: Literal["all"] | CurrentRange = "all"  # current positions homed to each goal
    methods: list[MethodEntry] = Field(min_length=1)  # method entries (labels distinct)
    metrics: MetricsConfig = MetricsConfig()  # AHC bins and definition, RR, catchment, bands
    rotate_current: RotationConfig = RotationConfig()  # seeded turns of the current views
    unfold: UnfoldConfig = UnfoldConfig()  # panoramas made from a raw-only database
    table_format: Literal["csv", "parquet"] = "csv"  # format of the tables in tables/
    checks: dict[str, Check] = Field(default_factory=dict)  # method label -> thresholds
    claims: list[ClaimEntry] = Field(default_factory=list)  # tested by `homebench findings`

    @field_validator("databases", mode="before")
    @classmethod
    def _names_as_refs(cls, value: Any) -> Any:
        if isinstance(value, dict):
            return {k: {"name": v} if isinstance(v, str) else v for k, v in value.items()}
        return value

    @field_validator("databases")
    @classmethod
    def _aliases(cls, value: dict[str, DatabaseRef]) -> dict[str, DatabaseRef]:
        if not value:
            raise ValueError("name at least one database")
        bad = [alias for alias in value if not ALIAS.match(alias)]
        if bad:
            raise ValueError(f"aliases may hold letters, digits and '_' only: {bad}")
        return value

    @field_validator("jobs")
    @classmethod
    def _jobs(cls, value: int) -> int:
        problem = workers_problem(value)
        if problem:
            raise ValueError(problem)
        return value

    @field_validator("seeds")
    @classmethod
    def _seeds(cls, value: list[int]) -> list[int]:
        if any(not 0 <= seed <= MAX_SWEPT_SEED for seed in value) or len(set(value)) != len(value):
            raise ValueError(
                f"seeds must be distinct, non-negative and at most {MAX_SWEPT_SEED} (the tables "
                "hold them as 64-bit integers)"
            )
        return value

    @field_validator("styles")
    @classmethod
    def _styles(cls, value: list[Style]) -> list[Style]:
        if len(set(value)) != len(value):
            raise ValueError("styles must be distinct")
        return value

    @model_validator(mode="after")
    def _references(self) -> RunConfig:
        problem = count_problem(self._counts(), "jobs")
        if problem:
            raise ValueError(problem)
        conditions = [] if self.conditions == "all" else self.conditions
        for k, condition in enumerate(conditions):
            parts = condition.split("-")
            if len(parts) != 2 or not all(parts):
                raise ValueError(f"conditions[{k}]: {condition!r} is not 'current-goal'")
            unknown = [p for p in parts if p not in self.databases]
            if unknown:
                hint = did_you_mean(unknown[0], self.databases)
                raise ValueError(
                    f"conditions[{k}]: unknown database alias {unknown[0]!r}"
                    + (hint or f"; defined: {', '.join(self.databases)}")
                )
        labels = [label for label, _, _ in self.method_points()]
        repeated = sorted({label for label in labels if labels.count(label) > 1})
        if repeated:
            raise ValueError(f"methods: label {repeated[0]!r} used twice; give each entry a label")
        unknown = sorted(set(self.checks) - set(labels))
        if unknown:
            raise ValueError(f"checks: no method entry labelled {unknown[0]!r}")
        names = [name for name, _, _ in self.condition_pairs()]
        for label, check in self.checks.items():
            missing = [c for c in check.conditions or [] if c not in names]
            if missing:
                raise ValueError(f"checks.{label}.conditions: {missing[0]!r} is not a condition")
        methods = {label: name for label, name, _ in self.method_points()}
        problem = claim_problem(self.claims, labels, names, "grid", methods)
        if problem:
            raise ValueError(problem)
        return self

    def _counts(self) -> dict[str, int]:
        """The counts whose product is the run's number of jobs, by the key that sets each (goals
        ``all`` count once here: the grid is known when the run is planned)."""
        goals: dict[str, int] = {}
        if isinstance(self.goals, list):
            goals = {"goals": len(self.goals)}
        elif isinstance(self.goals, RandomGoals):
            goals = {"goals.random": self.goals.random}
        conditions = len(self.databases) ** 2 if self.conditions == "all" else len(self.conditions)
        return {
            "seeds": len(self.seeds) or 1,
            "styles": len(self.styles) or 1,
            "conditions": conditions,
            "methods": sum(entry.n_points for entry in self.methods),
            **goals,
        }

    def condition_pairs(self) -> list[tuple[str, str, str]]:
        """(condition, current alias, goal alias) for every condition ("all": every ordered pair
        of aliases, the same database twice included)."""
        if self.conditions == "all":
            aliases = list(self.databases)
            return [(f"{c}-{g}", c, g) for c in aliases for g in aliases]
        return [(c, *c.split("-")) for c in self.conditions]

    def method_points(self) -> list[tuple[str, str, dict[str, Any]]]:
        """(label, method name, params) of every method entry and grid point, in config order."""
        return method_points(self.methods)

    def worlds(self) -> list[SweptWorld]:
        """The (style, seed) of every swept world, styles outermost; None where the config
        sweeps nothing (every generated database as configured)."""
        return [(style, seed) for style in self.styles or [None] for seed in self.seeds or [None]]


class ResolvedRunConfig(RunConfig):
    """A grid run's ``config.resolved.json``: its config as run, whose ``worker_memory_mb`` is
    the limit the workers had, which may lie below what a config may ask for (a Dask worker's
    share of its memory, an inherited ``ulimit -v``)."""

    worker_memory_mb: int | None = Field(None, ge=1)
    claims: list[RecordedClaim] = Field(default_factory=list)  # type: ignore[assignment]


#: The kinds of experiment a config declares with ``kind:`` (grid without one).
ROBOT_KINDS = ("route", "closed-loop")


def kind_of(data: Mapping[str, Any]) -> str:
    """The experiment kind of a config mapping: "route", "closed-loop" or "grid"."""
    kind = data.get("kind")
    return kind if kind in ROBOT_KINDS else "grid"


def load_config(path: Path, overrides: Sequence[str] = ()) -> RunConfig:
    """Read and validate a grid run config with ``key.path=value`` ``overrides``; every problem
    is a ConfigError naming file and key."""
    return grid_config(read_yaml(path, "config", overrides))


def grid_config(document: YamlDocument) -> RunConfig:
    """A grid run's config from its YAML document (:func:`homebench.yamlio.read_yaml`)."""
    config = validate(RunConfig, document)
    check_entries(Path(document.origin), config.methods)
    return config


def method_points(entries: Sequence[MethodEntry]) -> list[tuple[str, str, dict[str, Any]]]:
    """(label, method name, params) of every method entry and grid point, in order (the method
    lists of every kind of config)."""
    return [(label, entry.method, params) for entry in entries for label, params in entry.expand()]


def entry_problem(entry: MethodEntry, robot: str | None = None) -> str:
    """Why ``entry`` cannot run ("" when it can): its method cannot be made with its params,
    or, for a ``robot`` experiment (its kind's name), the method needs more than the one
    unfolded panorama a robot sees (a grid's neighbours, raw images)."""
    try:
        cls = registry.get(entry.method)
        for _, params in entry.expand():
            if "compass" in params and "compass" not in registry.parameters(entry.method):
                return (
                    f"params: compass is a key of the method entry, not a parameter of "
                    f"{entry.method}: write compass: {params['compass']} beside method:"
                )
            registry.create(entry.method, **params)
    except HomebenchError as error:
        return str(error)
    except (TypeError, ValueError) as error:
        return f"params: {error}"
    if robot is not None and not gives_direction(cls):
        return (
            f"{entry.method} gives no home direction (rotations only): it cannot steer a "
            f"{robot} robot; give another method `compass: visual` to use it as that method's "
            "compass"
        )
    if robot is not None and getattr(cls, "uses_neighbours", False):
        return (
            f"{entry.method} needs the views of the neighbouring grid positions; a {robot} robot "
            "has one view at a time"
        )
    if robot is not None and cls.image_kind != "unfolded":
        return (
            f"{entry.method} homes on {cls.image_kind} images; a {robot} robot sees unfolded "
            "panoramas (use its unfolded variant, e.g. sift-unfolded)"
        )
    return ""


def value_problem(entry: MethodEntry) -> str:
    """The first value of ``entry``'s ``params`` or ``grid`` that its parameter's type refuses
    (:mod:`homebench.methods.param_types`), with its key: "params.n_rho: expected an integer,
    got 2.5", "grid.n_rho.1: ..."; "" when there is none (an unknown method or parameter is
    :func:`entry_problem`'s to name)."""
    try:
        cls = registry.get(entry.method)
    except HomebenchError:
        return ""
    given = [(f"params.{name}", name, value) for name, value in entry.params.items()]
    given += [
        (f"grid.{name}.{i}", name, value)
        for name, values in entry.grid.items()
        for i, value in enumerate(values)
    ]
    for key, name, value in given:
        problem = parameter_problem(cls, name, value)
        if problem:
            return f"{key}: {problem}"
    return ""


def entry_error(k: int, entry: MethodEntry, robot: str | None = None) -> str:
    """What is wrong with ``entry``, the ``k``-th method entry, in one line that starts with
    its key ("methods.0.params.n_rho: ...", "methods.0: ..."); "" when nothing is
    (:func:`value_problem`, then :func:`entry_problem`)."""
    wrong = value_problem(entry)
    if wrong:
        return f"methods.{k}.{wrong}"
    problem = entry_problem(entry, robot)
    return f"methods.{k}: {problem}" if problem else ""


def check_entries(path: Path, entries: Sequence[MethodEntry], robot: str | None = None) -> None:
    """ConfigError naming the file and entry of the first entry with a problem
    (:func:`entry_error`)."""
    for k, entry in enumerate(entries):
        problem = entry_error(k, entry, robot)
        if problem:
            raise ConfigError(f"{path}: {problem}")
