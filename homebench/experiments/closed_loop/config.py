"""The config of a closed-loop homing experiment: YAML -> validated, frozen objects.

Dispatched on ``kind: closed-loop``. Example (see ``configs/closed_loop.yaml``)::

    kind: closed-loop
    name: closed-loop
    output: runs/closed_loop
    world: {seed: 0, style: posters}      # a generated world (WorldSpec), or
    # database: synth-original            # a grid database: the nearest grid images
    styles: [posters, lab]                # optional: sweep the world's style
    frame: grid                           # goals and starts in metres from the capture grid's
                                          # origin (one config fits every style), or world
    methods:                              # grid-config method entries (labels, params, grid)
      - {method: warping}
      - {method: alv, compass: truth}     # an external compass (see below)
    controls: [truth, random]             # built-in pseudo-methods (see homers.py)
    goals: [{at: [1.35, 2.4]}, {grid: [4, 8]}]   # metres, or capture-grid indices
    starts: {spacing: 0.3, region: [0, 0, 2.7, 4.8]}   # a lattice, or {random: 100, seed: 1}
    motion: {step_length: 0.1, max_turn_deg: 30, success_radius: 0.15, budget_factor: 3}
    render: {lattice: 0.02}
    training: {routes: 8, length_m: 1.5, spacing_m: 0.1}  # route-learning methods' views
    job_timeout_s: 3600                   # a trial running longer fails (null: never)
    claims:                               # tested by `homebench findings` (claim_spec.py)
      - {better: warping, than: random, metric: success}
      - {better: warping, than: alv, metric: final_error, condition: lab, margin: 0.05}

Defaults and why:

- ``motion.step_length`` 0.10 m, ``max_turn_deg`` 30: a tenth of a typical start distance per
  step keeps the loop affordable (every step is a render) while the turn limit still lets a
  robot facing away turn round in 6 steps.
- ``success_radius`` 0.15 m: half the papers' 0.30 m grid spacing (seed 001's RR success
  radius of 0.5 grid units).
- ``budget_factor`` 3: give up after 3 x the straight-line start distance (seed 001's RR
  gives up after half the grid's perimeter; a factor scales with the start instead);
  ``budget_m`` (None) adds an absolute cap; ``max_steps`` 150 bounds turning on the spot (a
  method that never points within the turn limit turns for ever): 3 x the 50 driving steps of
  a 5 m budget.
- ``min_start_distance`` 2 x the success radius: a start must not begin at home.
- ``no_estimate: continue``: drive straight on (the previous heading), as a robot whose
  controller keeps its last command; ``stop`` ends the trial.
- a method entry's ``compass`` (``none``, as in grid configs): ``truth`` is an external compass
  (the robot turns its view to the goal snapshot's heading before asking, as the papers align
  their views), ``visual`` the visual compass (the view turned back by the RIDF minimum against
  the goal snapshot); with ``none`` the method sees the view at the robot's own heading.
- ``render.lattice`` 0.02 m: views are rendered at positions snapped to a 2 cm lattice, below
  the step length, so the snapping moves the camera by at most 1.4 cm.
- ``training`` (methods that learn a route, ``learns_route``: perfect-memory, infomax): they
  home by the familiarity of views learnt on ``routes`` straight routes into each goal, 8 from
  equally spaced directions (the first from straight ahead of the goal's heading), each 1.5 m
  long (the starts' distances), a view every 0.1 m (the step length) facing the goal, learnt
  from the far end in: the routes an animal's first trips to a place would leave, the paper's
  training views (facing the way to go) in every direction a start may lie.

- ``claims`` (:mod:`homebench.claim_spec`): ``success`` or ``final_error`` (the trial's final
  distance to its goal, metres) of two labels (method entries or controls), optionally under
  one world ``condition`` (a style of the run; ``database`` for a database run); recorded with
  when each was stated in ``config.resolved.json`` before any trial runs.

Checks that need the world (goals in free space) happen when the experiment starts.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    Discriminator,
    Field,
    FiniteFloat,
    SerializerFunctionWrapHandler,
    Tag,
    field_validator,
    model_serializer,
    model_validator,
)

from homebench.bounds import MAX_TRIAL_FRAMES, count_problem
from homebench.claim_spec import ClaimEntry, RecordedClaim, claim_problem
from homebench.config import (
    DEFAULT_JOB_TIMEOUT_S,
    JobTimeout,
    MethodEntry,
    UnfoldConfig,
    method_points,
)
from homebench.data.synth.spec import Style, WorldSpec
from homebench.experiments.memory import check_robot_entries, is_memory_method
from homebench.experiments.robot import DriftModel, MotionLimits
from homebench.geometry import Pose, wrap_angle
from homebench.strict import StrictModel
from homebench.yamlio import YamlDocument, read_yaml, validate

#: The style name of a database run's trials (it has no world style).
DATABASE_STYLE = "database"
Control = Literal["truth", "random"]
CONTROLS: tuple[Control, ...] = ("truth", "random")
#: Region of the floor: (x_min, y_min, x_max, y_max), metres.
Region = tuple[FiniteFloat, FiniteFloat, FiniteFloat, FiniteFloat]


class GoalSpec(StrictModel):
    """A goal: ``at`` (x, y) metres in the config's frame, or ``grid`` (i, j) capture-grid
    indices; ``heading_deg`` of its snapshot (default 0)."""

    at: tuple[FiniteFloat, FiniteFloat] | None = None  # (x, y) metres in the config's frame
    grid: tuple[int, int] | None = None  # (i, j) capture-grid indices (instead of at)
    heading_deg: FiniteFloat = 0.0  # the goal snapshot's heading, degrees ccw from +x

    @model_validator(mode="before")
    @classmethod
    def _bare_point(cls, data: Any) -> Any:
        return {"at": data} if isinstance(data, list | tuple) else data

    @model_validator(mode="after")
    def _one_place(self) -> GoalSpec:
        if (self.at is None) == (self.grid is None):
            raise ValueError("give a goal exactly one of 'at' (metres) and 'grid' (indices)")
        return self


def _ordered(region: Region | None) -> Region | None:
    if region is not None and not (region[0] < region[2] and region[1] < region[3]):
        raise ValueError(f"region {list(region)} is not [x_min, y_min, x_max, y_max]")
    if region is not None and not math.isfinite((region[2] - region[0]) * (region[3] - region[1])):
        raise ValueError(f"region {list(region)}: its area is no finite number of m^2")
    return region


class LatticeStarts(StrictModel):
    """Starts on a square lattice of ``spacing`` metres over ``region`` (default: the capture
    grid's extent), the first node at the region's corner; each start's cell is spacing^2.
    ``heading_deg``: every start's heading (world frame); None: seeded uniform headings."""

    spacing: float = Field(gt=0)  # lattice spacing, metres
    # [x_min, y_min, x_max, y_max] metres in the config's frame; None: the capture grid's extent
    region: Region | None = None
    # every start's heading, degrees (world frame); None: seeded uniform headings
    heading_deg: FiniteFloat | None = None

    _region = field_validator("region")(_ordered)

    def shape(self, region: Region) -> tuple[int, int]:
        """(columns, rows) of the lattice over ``region``."""
        x0, y0, x1, y1 = region
        nx = math.floor((x1 - x0) / self.spacing + 1e-6) + 1  # 1e-6: a region of k spacings
        ny = math.floor((y1 - y0) / self.spacing + 1e-6) + 1
        return nx, ny


class RandomStarts(StrictModel):
    """``random`` starts drawn uniformly over ``region`` (seeded by ``seed``); each stands for
    region area / random of the floor. ``heading_deg`` as for lattice starts."""

    random: int = Field(ge=1)  # how many starts to draw
    seed: int = Field(0, ge=0)  # seed of the starts' positions and headings
    # [x_min, y_min, x_max, y_max] metres in the config's frame; None: the capture grid's extent
    region: Region | None = None
    # every start's heading, degrees (world frame); None: seeded uniform headings
    heading_deg: FiniteFloat | None = None

    _region = field_validator("region")(_ordered)


def _starts_kind(data: Any) -> str:
    """Which starts a mapping gives: "random" when it has that key, else "lattice"."""
    keys = data if isinstance(data, dict) else vars(data)
    return "random" if "random" in keys else "lattice"


Starts = Annotated[
    Annotated[LatticeStarts, Tag("lattice")] | Annotated[RandomStarts, Tag("random")],
    Discriminator(_starts_kind),
]


class ClosedLoopMotion(MotionLimits):
    """The robot's step and turn limits (:class:`MotionLimits`) and when a trial ends."""

    step_length: float = Field(0.10, gt=0)  # most the robot drives in one step, metres
    max_turn_deg: float = Field(30.0, gt=0, le=180)  # most it turns in one step, degrees
    success_radius: float = Field(0.15, gt=0)  # success: the true position this near the goal, m
    # give up after this many times the straight-line start distance (None: budget_m alone)
    budget_factor: float | None = Field(3.0, ge=1)
    budget_m: float | None = Field(None, gt=0)  # an absolute cap on the path driven, metres
    max_steps: int = Field(150, ge=1, le=MAX_TRIAL_FRAMES)  # steps (turns included) a trial gets
    # closest a start may be to its goal, metres; None: 2 x success_radius
    min_start_distance: float | None = Field(None, ge=0)
    # a step without an estimate: continue (drive straight on, counted) or stop the trial
    no_estimate: Literal["continue", "stop"] = "continue"

    @model_validator(mode="after")
    def _budget(self) -> ClosedLoopMotion:
        if self.budget_factor is None and self.budget_m is None:
            raise ValueError("give a path budget: budget_factor, budget_m or both")
        if self.min_start_distance is not None and self.min_start_distance <= self.success_radius:
            raise ValueError("min_start_distance must exceed success_radius")
        return self

    def limits(self) -> MotionLimits:
        return MotionLimits(step_length=self.step_length, max_turn_deg=self.max_turn_deg)

    def budget(self, start_distance: float) -> float:
        """Path length (m) after which a trial from ``start_distance`` metres gives up."""
        caps = [
            *([self.budget_factor * start_distance] if self.budget_factor is not None else []),
            *([self.budget_m] if self.budget_m is not None else []),
        ]
        return min(caps)

    @property
    def start_floor(self) -> float:
        """Closest a start may be to its goal, metres."""
        if self.min_start_distance is not None:
            return self.min_start_distance
        return 2.0 * self.success_radius


class RenderConfig(StrictModel):
    """Views of a generated world: rendered at heading 0 on a ``lattice`` (metres) and turned
    by whole columns; ``cache_mb`` bounds the run folder's view cache, ``memory_views`` each
    worker's in-memory LRU. ``lattice: null`` renders every pose exactly (no cache)."""

    # views rendered at positions snapped to this lattice, metres; null: every pose exactly
    lattice: float | None = Field(0.02, gt=0)
    cache_mb: float = Field(2000.0, ge=0)  # most the run folder's view cache holds, MB
    memory_views: int = Field(512, ge=0)  # views each worker keeps in memory (LRU)


class TrainingRoutes(StrictModel):
    """What methods that learn a route learn for each goal: ``routes`` straight routes into it
    from equally spaced directions, ``length_m`` long, a view every ``spacing_m`` metres facing
    the goal (see the module docstring)."""

    routes: int = Field(8, ge=1)  # straight training routes into each goal, equally spaced
    length_m: float = Field(1.5, gt=0)  # length of each training route, metres
    spacing_m: float = Field(0.1, gt=0)  # a training view every this many metres

    @model_validator(mode="after")
    def _bounded(self) -> TrainingRoutes:
        views = self.routes * (self.length_m / self.spacing_m)
        if views > MAX_TRIAL_FRAMES:
            raise ValueError(
                f"routes x length_m / spacing_m: {views:,.0f} training views per goal, more "
                f"than the {MAX_TRIAL_FRAMES:,} one trial can hold"
            )
        return self

    def poses(self, goal: Pose) -> list[Pose]:
        """The training poses for ``goal``, in learning order: route by route (ccw from the
        goal's heading), each from its far end in, facing the goal."""
        count = math.floor(self.length_m / self.spacing_m + 1e-9)
        distances = self.spacing_m * np.arange(count, 0, -1)
        poses = []
        for r in range(self.routes):
            away = goal.heading + 2.0 * math.pi * r / self.routes
            for d in distances:
                x, y = goal.x + d * math.cos(away), goal.y + d * math.sin(away)
                poses.append(Pose(float(x), float(y), float(wrap_angle(away + math.pi))))
        return poses


class ClosedLoopConfig(StrictModel):
    """A closed-loop homing experiment: a scene, methods and controls, goals, starts, motion."""

    kind: Literal["closed-loop"]  # a closed-loop homing experiment
    name: str = "closed-loop"  # the run's name in tables and reports
    output: Path  # the run folder (relative to the current directory)
    # seeds lattice starts' headings, the random control, motion noise and the views' sensor noise
    seed: int = Field(0, ge=0)
    # parallel workers (-1: all cores; homebench run --jobs overrides it)
    jobs: Annotated[int, Field(ge=1)] | Literal[-1] = 1
    job_timeout_s: JobTimeout = DEFAULT_JOB_TIMEOUT_S  # a trial running longer fails
    world: WorldSpec = WorldSpec()  # the generated world the robot homes in (unless database)
    styles: list[Style] = Field(default_factory=list)  # sweep the world's style (distinct)
    # or a database (known name, manifest path or Brains on Board folder): the nearest grid image
    database: str | None = None
    database_path: Path | None = None  # folder of a real set's copy (needs database)
    unfold: UnfoldConfig = UnfoldConfig()  # panoramas made from a raw-only database
    # goals and starts in metres from the capture grid's origin (grid) or world coordinates
    frame: Literal["world", "grid"] = "grid"
    methods: list[MethodEntry] = Field(default_factory=list)  # method entries, as a grid config's
    # built-in pseudo-methods: truth (the true home direction), random (chance level)
    controls: list[Control] = Field(default_factory=lambda: list(CONTROLS))
    goals: list[GoalSpec] = Field(min_length=1)  # the goals, each homed to from every start
    starts: Starts  # start positions: a lattice ({spacing: ...}) or random ({random: N})
    motion: ClosedLoopMotion = ClosedLoopMotion()  # step and turn limits, when a trial ends
    drift: DriftModel = DriftModel()  # odometry errors (default: none)
    render: RenderConfig = RenderConfig()  # how views of a generated world are rendered, cached
    training: TrainingRoutes = TrainingRoutes()  # what route-learning methods learn per goal
    claims: list[ClaimEntry] = Field(default_factory=list)  # tested by `homebench findings`

    @model_serializer(mode="wrap")
    def _omit_unused(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields, without ``training`` when no method learns a route and without
        ``claims`` when there are none (a resolved config, and its hash, as before closed
        loops had such methods or claims)."""
        data = handler(self)
        if not any(is_memory_method(entry.method) for entry in self.methods):
            data.pop("training", None)
        if not self.claims:
            data.pop("claims", None)
        return data

    @model_validator(mode="after")
    def _checks(self) -> ClosedLoopConfig:
        if self.database is not None and ("world" in self.model_fields_set or self.styles):
            raise ValueError("give either 'world' (and 'styles') or 'database', not both")
        if self.database_path is not None and self.database is None:
            raise ValueError("'database_path' needs 'database'")
        if len(set(self.styles)) != len(self.styles):
            raise ValueError("styles must be distinct")
        if len(set(self.controls)) != len(self.controls):
            raise ValueError("controls must be distinct")
        if not self.methods and not self.controls:
            raise ValueError("name at least one method or control")
        problem = self.count_problem()
        if problem:
            raise ValueError(problem)
        labels = [label for label, _, _ in self.method_points()] + list(self.controls)
        repeated = sorted({label for label in labels if labels.count(label) > 1})
        if repeated:
            raise ValueError(
                f"methods: label {repeated[0]!r} used twice (controls are labelled truth and "
                "random); give each entry a label"
            )
        methods = {label: name for label, name, _ in self.method_points()}
        styles = self.style_names()
        problem = claim_problem(self.claims, labels, styles, "closed-loop", methods)
        if problem:
            raise ValueError(problem)
        return self

    def count_problem(self, region: Region | None = None) -> str:
        """Why the run would hold more trials than one run can ("" when it would not): styles x
        goals x starts x labels. Lattice starts are counted over ``region``, else over the
        starts' own region or the world's capture grid (a database's grid is known only when
        the run starts: it asks again with its region)."""
        starts = self.starts
        if isinstance(starts, RandomStarts):
            counted = {"starts.random": starts.random}
        else:
            region = region or starts.region or self._grid_extent()
            counted = {"starts.spacing": math.prod(starts.shape(region))} if region else {}
        labels = sum(entry.n_points for entry in self.methods) + len(self.controls)
        counts = {"styles": len(self.styles) or 1, "goals": len(self.goals), **counted}
        return count_problem({**counts, "methods": labels}, "trials")

    def _grid_extent(self) -> Region | None:
        """The capture grid's extent from its first position (None for a database)."""
        if self.database is not None:
            return None
        grid = self.world.to_grid()
        return (0.0, 0.0, *((n - 1) * grid.spacing for n in grid.shape))

    def method_points(self) -> list[tuple[str, str, dict[str, Any]]]:
        """(label, method name, params) of every method entry and grid point, config order."""
        return method_points(self.methods)

    def labels(self) -> list[str]:
        """Every method label, then the controls."""
        return [label for label, _, _ in self.method_points()] + list(self.controls)

    def style_names(self) -> list[str]:
        """The style of each swept world, config order (:data:`DATABASE_STYLE` for a
        database run): the conditions a claim may name."""
        return [DATABASE_STYLE if w is None else w.style for w in self.worlds()]

    def worlds(self) -> list[WorldSpec | None]:
        """The world of each swept style (the world itself without styles); [None] for a
        database."""
        if self.database is not None:
            return [None]
        return [self.world.model_copy(update={"style": s}) for s in self.styles] or [self.world]


class ResolvedClosedLoopConfig(ClosedLoopConfig):
    """A closed-loop run's ``config.resolved.json``: its claims with when each was stated
    (:func:`~homebench.evaluation.claims_record.stamped_claims`)."""

    claims: list[RecordedClaim] = Field(default_factory=list)  # type: ignore[assignment]


def load_closed_loop_config(path: Path, overrides: Sequence[str] = ()) -> ClosedLoopConfig:
    """Read and validate a closed-loop config with ``key.path=value`` ``overrides``; problems
    are ConfigErrors naming file and key. Methods are checked by creating them."""
    return closed_loop_config(read_yaml(path, "config", overrides))


def closed_loop_config(document: YamlDocument) -> ClosedLoopConfig:
    """A closed-loop run's config from its YAML document (:func:`homebench.yamlio.read_yaml`)."""
    config = validate(ClosedLoopConfig, document)
    check_robot_entries(document.origin, config.methods, robot="closed-loop")
    return config
