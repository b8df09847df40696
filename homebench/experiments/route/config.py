"""The config of a route-homing experiment (seed 000): YAML -> validated, frozen objects.

Dispatched on ``kind: route`` (grid-database runs are :mod:`homebench.config`). Example (see
``configs/klt_route.yaml``)::

    kind: route
    name: klt-route
    output: runs/klt_route
    world: {seed: 0, variant: original}          # a generated world (WorldSpec), or
    # database: synth-original                   # a grid database: nearest grid images, or
    # database: ~/data/ant_route1                # a recorded route (waypoints: recorded)
    # recorded_reach_m: 0.3                      #   seen this far from it (default: spacing)
    routes:
      - name: tour
        waypoints: [[1.7, 1.8], [1.7, 3.8], [4.2, 3.8]]   # metres, world frame; home first
        lengths: [2, 4]                          # one trial per length: the route's first metres
        displacements_m: [0.0, 0.3]              # optional: homing starts carried off the end
    motion: {step_length: 0.05, max_turn_deg: 10}
    drift: {translation_var: 1.0e-4, heading_bias: 0.01}
    tracker: {max_corners: 150, min_tracks: 100}  # KltTracker parameters
    homing: {min_shared: 80, goal_threshold: 0.01}
    methods:                                     # grid-config method entries (default:
      - {method: klt-sector}                     #   klt-sector alone)
      - {method: warping, label: warping-fine, params: {n_rho: 40}}
      - {method: infomax}                        # a route-learning method
    pairwise:                                    # the pairwise methods
      snapshots: {rule: spacing, spacing_m: 0.5} # or {rule: similarity, threshold: 12}
      arrival: {criterion: minimum, patience: 2} # or {criterion: oracle, radius_m: 0.05}
    familiarity:                                 # the route-learning methods
      near_home_m: 1.0                           # arrival watched this near home (odometry)
      probes: {spacing_m: 0.5, offsets_m: [-0.5, 0, 0.5]}   # heading field beside the route
    success_radius_m: 0.1                        # success: the final position this near home
    job_timeout_s: 3600                          # a trial running longer fails (null: never)
    claims:                                      # tested by `homebench findings`
      - {better: klt-sector, than: odometry, metric: final_error, condition: tour}
      - {better: warping-fine, than: infomax, metric: success, margin: 0.1}

``klt-sector`` keeps seed 000's own route homing (KLT tracking on the way out, intermediate
positions from the feature life-cycles, the sector law; set by ``tracker`` and ``homing``, so its
entry takes no ``params``). Methods that learn a route (``learns_route``: perfect-memory,
infomax) learn every outbound view and follow their memory home
(:mod:`~homebench.experiments.route.familiar`, set by ``familiarity``); they take no
``compass``. Every other method homes through snapshots
(:mod:`~homebench.experiments.route.pairwise`, set by ``pairwise``). It must be pairwise (no
grid neighbours, like DID) and work on unfolded panoramas, which is what the scene renders
(``sift-unfolded`` for the SIFT family).

``claims`` (:mod:`homebench.claim_spec`): ``success`` (the trial ends within
``success_radius_m`` of home) or ``final_error`` (its final distance to home, metres) of two
method labels, or of a label and ``odometry`` (the odometry baseline of the same trials,
:data:`ODOMETRY`), optionally on one route (``condition``: a route's name); recorded with when
each was stated in ``config.resolved.json`` before any trial runs.

Checks that need the world (waypoints in free space, or within a database's grid) happen when
the experiment starts.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import (
    Field,
    FiniteFloat,
    SerializerFunctionWrapHandler,
    ValidationError,
    field_validator,
    model_serializer,
    model_validator,
)

from homebench.bounds import MAX_FRAMES, MAX_TRIAL_FRAMES, count_problem
from homebench.claim_spec import ClaimEntry, RecordedClaim, claim_problem
from homebench.config import (
    ALIAS,
    DEFAULT_JOB_TIMEOUT_S,
    JobTimeout,
    MethodEntry,
    UnfoldConfig,
    method_points,
)
from homebench.data.synth.spec import WorldSpec
from homebench.errors import ConfigError
from homebench.experiments.memory import is_memory_method, robot_entry_error
from homebench.experiments.robot import DriftModel, MotionLimits
from homebench.experiments.route.familiar import FamiliarityParams
from homebench.experiments.route.pairwise import PairwiseParams
from homebench.experiments.route.visual import VisualHomingParams
from homebench.methods.klt_sector.tracking import KltTracker
from homebench.strict import StrictModel
from homebench.yamlio import YamlDocument, read_yaml, validate

#: The method that homes with seed 000's own route homing (life-cycles, sector law).
KLT_SECTOR = "klt-sector"
#: The odometry baseline's label: every trial also homes by odometry alone.
ODOMETRY = "odometry"
#: The waypoints of a route that follows its database's recorded poses.
RECORDED = "recorded"
#: Recorded poses closer than this (metres) to the last one a replayed route keeps are dropped
#: (a robot standing still while it records).
MIN_STEP_M = 1e-3


class RouteSpec(StrictModel):
    """An outbound route: ``waypoints`` (metres, home first) driven in order.

    ``frame``: ``world`` (the waypoints are world coordinates) or ``grid`` (metres from the
    capture grid's origin, position (0, 0): one route then fits every generated style, whose
    grids are centred in rooms of different sizes; on a recording, from its first pose).
    ``waypoints: recorded`` follows the poses of the config's database, a recorded route (a
    Brains on Board folder that is no grid), in recording order: the route replays its images
    (:func:`~homebench.experiments.scene.posed_scene`).

    ``heading_deg``: the robot's heading at home (default: along the first segment).
    ``lengths`` (metres): one trial per length, driving the route's first metres; default: one
    trial over the whole route. ``displacements_m``: one trial per value, the robot carried
    that many metres to the left (negative: right) of the route's last segment before it
    homes, its odometry not told (default: it homes from the route's end). ``repeats``:
    trials per length and displacement, each with its own noise.
    """

    name: str  # the route's name in tables (letters, digits, '_'); a claim's condition
    # [x, y] points, metres, home first; or 'recorded': the database's recorded poses
    # (None: 'recorded' as the config gives it; a plain list type keeps the errors of a list's)
    waypoints: Annotated[list[tuple[FiniteFloat, FiniteFloat]], Field(min_length=2)] | None
    # world: the waypoints are world coordinates; grid: metres from the capture grid's origin
    frame: Literal["world", "grid"] = "world"
    # the robot's heading at home, degrees ccw from +x; None: along the first segment
    heading_deg: FiniteFloat | None = None
    # metres driven out along the route, one trial each; None: one trial, the whole route
    lengths: list[Annotated[float, Field(gt=0)]] | None = None
    # metres the robot is carried left (negative: right) of the route's end before homing,
    # one trial each, odometry not told; None: it homes from the route's end
    displacements_m: list[FiniteFloat] | None = Field(None, min_length=1)
    repeats: int = Field(1, ge=1)  # trials per length and displacement, each with its own noise

    @field_validator("name")
    @classmethod
    def _name(cls, value: str) -> str:
        if not ALIAS.match(value):
            raise ValueError(f"route names may hold letters, digits and '_' only: {value!r}")
        return value

    @property
    def is_recorded(self) -> bool:
        """Whether the route follows its database's recorded poses (``waypoints: recorded``)."""
        return self.waypoints is None

    @model_validator(mode="before")
    @classmethod
    def _recorded(cls, data: Any) -> Any:
        """``waypoints: recorded`` read as None (a null is no route)."""
        if isinstance(data, dict) and "waypoints" in data:
            if data["waypoints"] is None:
                raise ValueError("waypoints: give a list of [x, y] points or 'recorded'")
            if data["waypoints"] == RECORDED:
                return {**data, "waypoints": None}
        return data

    @property
    def length(self) -> float:
        """Length of the whole route, metres (of a recorded route: once replayed)."""
        assert not self.is_recorded, "a recorded route has a length once replayed"
        return float(np.sum(np.hypot(*np.diff(np.asarray(self.waypoints), axis=0).T)))

    def frames(self, motion: MotionLimits) -> float:
        """Most frames a drive of the whole route can take under ``motion``: a step per
        ``step_length`` metres, and on every segment a turn of up to 180 deg in steps of
        ``max_turn_deg`` (each count rounded up); inf for a route of infinite length."""
        segments = len(self.waypoints) - 1
        turns = 180.0 / motion.max_turn_deg + 2.0
        return self.length / motion.step_length + segments * turns + 1.0

    def frames_problem(self, key: str, motion: MotionLimits) -> str:
        """Why a drive of the route (config key ``key``) would take more frames than one trial
        can hold (:data:`~homebench.bounds.MAX_TRIAL_FRAMES`), naming the key; "" otherwise."""
        frames = self.frames(motion)
        if frames <= MAX_TRIAL_FRAMES:
            return ""
        shown = f"{frames:,.0f}" if frames < 1e15 else f"{frames:.3g}"
        return (
            f"{key}.waypoints: a route of {self.length:.6g} m at motion.step_length "
            f"{motion.step_length:g} m (turning motion.max_turn_deg {motion.max_turn_deg:g} deg "
            f"a step) takes up to {shown} frames, more than the {MAX_TRIAL_FRAMES:,} one trial "
            "can hold"
        )

    @model_serializer(mode="wrap")
    def _omit_displacements(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields, without ``displacements_m`` when not given (a resolved config, and its
        hash, as before routes had displacements); recorded waypoints as ``recorded``."""
        data = handler(self)
        if self.displacements_m is None:
            data.pop("displacements_m", None)
        if self.is_recorded:
            data["waypoints"] = RECORDED
        return data

    @model_validator(mode="after")
    def _lengths_fit(self) -> RouteSpec:
        if self.is_recorded:  # checked once replayed (replayed())
            if self.frame != "world":
                raise ValueError("recorded waypoints are the database's poses: frame 'world'")
            return self
        if self.length <= 0:
            raise ValueError("the waypoints must not all coincide")
        too_long = [x for x in self.lengths or () if x > self.length + 1e-9]
        if too_long:
            raise ValueError(f"length {too_long[0]} m exceeds the route's {self.length:.3f} m")
        return self

    def replayed(self, xy: NDArray[np.float64], where: str, motion: MotionLimits) -> RouteSpec:
        """This recorded route along the recorded poses ``xy`` (n, 2), metres, in order; poses
        within :data:`MIN_STEP_M` of the last one kept are dropped. ConfigError starting with
        ``where`` when the poses do not make the route (its lengths too long, more frames under
        ``motion`` than a trial can hold)."""
        kept = [xy[0]]
        for point in xy[1:]:
            if math.dist(point, kept[-1]) >= MIN_STEP_M:
                kept.append(point)
        waypoints = [(float(x), float(y)) for x, y in kept]
        try:
            route = RouteSpec.model_validate(self.model_dump() | {"waypoints": waypoints})
        except ValidationError as error:
            problem = error.errors()[0]
            raise ConfigError(f"{where}: the recorded poses: {problem['msg']}") from None
        problem = route.frames_problem("the recorded poses", motion)
        if problem:
            raise ConfigError(f"{where}: {problem}")
        return route

    def in_world(self, grid_origin: tuple[float, float]) -> RouteSpec:
        """This route with world-frame waypoints (``grid_origin``: the capture grid's, metres)."""
        if self.frame == "world":
            return self
        x0, y0 = grid_origin
        waypoints = [(x + x0, y + y0) for x, y in self.waypoints]
        return self.model_copy(update={"waypoints": waypoints, "frame": "world"})

    def trial_lengths(self) -> list[float]:
        return list(self.lengths) if self.lengths else [self.length]

    @property
    def trials_per_repeat(self) -> int:
        """Trials of one repeat: lengths x displacements."""
        return len(self.lengths or [None]) * len(self.displacements_m or [None])

    @property
    def heading(self) -> float:
        """Heading at home, radians."""
        if self.heading_deg is not None:
            return math.radians(self.heading_deg)
        (x0, y0), (x1, y1) = self.waypoints[0], self.waypoints[1]
        return math.atan2(y1 - y0, x1 - x0)


class RouteConfig(StrictModel):
    """A route-homing experiment: a generated world, routes, the robot, the tracker, homing."""

    kind: Literal["route"]  # a route-homing experiment
    name: str = "route"  # the run's name in tables and reports
    output: Path  # the run folder (relative to the current directory)
    # seeds each trial's motion and sensor noise and its probes' headings (with its name)
    seed: int = Field(0, ge=0)
    # parallel workers (-1: all cores; homebench run --jobs overrides it)
    jobs: Annotated[int, Field(ge=1)] | Literal[-1] = 1
    job_timeout_s: JobTimeout = DEFAULT_JOB_TIMEOUT_S  # a trial running longer fails
    world: WorldSpec = WorldSpec()  # the generated world the robot drives in (unless database)
    # Or a database (known name, manifest path or Brains on Board folder): the robot sees the
    # nearest grid image, or the nearest recorded image of a recorded route.
    database: str | None = None
    database_path: Path | None = None  # folder of a real set's copy
    # A recorded route's reach (metres): how far from every recorded pose the robot still sees
    # the nearest recorded image; None: the recording's sparsest spacing.
    recorded_reach_m: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None
    unfold: UnfoldConfig = UnfoldConfig()  # panoramas made from a raw-only database
    routes: list[RouteSpec] = Field(min_length=1)  # the outbound routes (names distinct)
    motion: MotionLimits = MotionLimits()  # the robot's step and turn per frame
    drift: DriftModel = DriftModel()  # odometry errors (default: none, exact dead reckoning)
    # klt-sector's corner tracker: KltTracker's parameters (default: its own defaults)
    tracker: dict[str, Any] = Field(default_factory=dict)
    homing: VisualHomingParams = VisualHomingParams()  # klt-sector's route homing
    # method entries, as a grid config's (default: klt-sector alone); labels distinct
    methods: list[MethodEntry] = Field(
        default_factory=lambda: [MethodEntry(method=KLT_SECTOR)], min_length=1
    )
    pairwise: PairwiseParams = PairwiseParams()  # how the pairwise methods home (snapshots)
    familiarity: FamiliarityParams = FamiliarityParams()  # how route-learning methods home
    success_radius_m: float = Field(0.1, gt=0)  # a trial succeeds ending this near home, metres
    claims: list[ClaimEntry] = Field(default_factory=list)  # tested by `homebench findings`

    @model_validator(mode="after")
    def _checks(self) -> RouteConfig:
        if self.database is not None and "world" in self.model_fields_set:
            raise ValueError("give either 'world' or 'database', not both")
        if self.database_path is not None and self.database is None:
            raise ValueError("'database_path' needs 'database'")
        if self.recorded_reach_m is not None and self.database is None:
            raise ValueError("'recorded_reach_m' is for a recorded route: it needs 'database'")
        recorded = [k for k, route in enumerate(self.routes) if route.is_recorded]
        if recorded and self.database is None:
            raise ValueError(
                f"routes.{recorded[0]}: waypoints 'recorded' follow a database's recorded poses; "
                "give 'database' (a Brains on Board route folder)"
            )
        problem = self._size_problem()
        if problem:
            raise ValueError(problem)
        names = [route.name for route in self.routes]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise ValueError(f"routes: name {repeated[0]!r} used twice")
        try:
            self.klt()
        except (TypeError, ConfigError) as error:
            raise ValueError(f"tracker: {error}") from None
        labels = [label for label, _, _ in self.method_points()]
        repeated = sorted({label for label in labels if labels.count(label) > 1})
        if repeated:
            raise ValueError(f"methods: label {repeated[0]!r} used twice; give each entry a label")
        for k, entry in enumerate(self.methods):
            problem = _method_problem(k, entry)
            if problem:
                raise ValueError(problem)
        methods = {label: name for label, name, _ in self.method_points()}
        problem = claim_problem(self.claims, [*labels, ODOMETRY], names, "route", methods)
        if problem:
            raise ValueError(problem)
        return self

    @model_serializer(mode="wrap")
    def _omit_unused(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields, without ``pairwise`` and ``familiarity`` when no method uses them and
        without ``methods`` and ``success_radius_m`` when not given: a klt-sector run's
        resolved config (and its hash) is the same as before route runs had other methods;
        without ``world`` when the scene is a ``database``."""
        data = handler(self)
        kinds = {_kind(name) for _, name, _ in self.method_points()}
        for kind in ("pairwise", "familiarity"):
            if kind not in kinds:
                data.pop(kind, None)
        for name in ("methods", "success_radius_m", "recorded_reach_m"):
            if name not in self.model_fields_set:
                data.pop(name, None)
        if not self.claims:  # as before route runs had claims
            data.pop("claims", None)
        if self.database is not None:  # no world then: the resolved config reads back
            data.pop("world", None)
        return data

    def _size_problem(self) -> str:
        """Why the run would hold more than one run can, naming the keys ("" when it would
        not): more trials (every route's lengths x repeats x the methods; the counts of the
        route with the most), a route of more frames than a trial can hold, or more frames in
        all (each route's frames x its trials x the methods; the counts of the route with the
        most). A recorded route is counted once replayed (:meth:`RouteSpec.replayed`)."""
        trials = [route.trials_per_repeat * route.repeats for route in self.routes]
        methods = sum(entry.n_points for entry in self.methods)
        k = trials.index(max(trials))
        problem = count_problem(self._counts(k, methods), "trials", total=sum(trials) * methods)
        drawn = [(k, route) for k, route in enumerate(self.routes) if not route.is_recorded]
        for k, route in drawn:
            problem = problem or route.frames_problem(f"routes[{k}]", self.motion)
        if problem or not drawn:
            return problem
        frames = {k: math.ceil(route.frames(self.motion)) for k, route in drawn}
        k = max(frames, key=lambda k: frames[k] * trials[k])
        counts = {**self._counts(k, methods), f"routes[{k}].waypoints": frames[k]}
        total = sum(n * trials[k] for k, n in frames.items()) * methods
        return count_problem(counts, "frames", MAX_FRAMES, total=total)

    def _counts(self, k: int, methods: int) -> dict[str, int]:
        """The counts whose product is route ``k``'s trials, by the key that sets each."""
        route = self.routes[k]
        return {
            f"routes[{k}].repeats": route.repeats,
            f"routes[{k}].lengths": len(route.lengths or [None]),
            f"routes[{k}].displacements_m": len(route.displacements_m or [None]),
            "methods": methods,
        }

    def method_points(self) -> list[tuple[str, str, dict[str, Any]]]:
        """(label, method name, params) of every method entry and grid point, in order."""
        return method_points(self.methods)

    def scene_key(self) -> dict[str, Any]:
        """What identifies the scene in trial keys: the database and what it holds
        (:func:`~homebench.experiments.scene.database_content`), or the world spec's hash."""
        if self.database is not None:
            from homebench.experiments.scene import database_content  # opens the database

            reach = {} if self.recorded_reach_m is None else {"reach": self.recorded_reach_m}
            content = database_content(self.database, self.database_path)
            return {"database": self.database, "path": str(self.database_path),
                    "content": content, **reach}  # fmt: skip
        return {"world": self.world.key()}

    def klt(self) -> KltTracker:
        """The corner tracker of the run."""
        return KltTracker(**self.tracker)


class ResolvedRouteConfig(RouteConfig):
    """A route run's ``config.resolved.json``: its claims with when each was stated
    (:func:`~homebench.evaluation.claims_record.stamped_claims`)."""

    claims: list[RecordedClaim] = Field(default_factory=list)  # type: ignore[assignment]


def _kind(name: str) -> str:
    """How a route run homes with method ``name``: ``klt-sector`` (its own route homing),
    ``familiarity`` (a route-learning method follows its memory) or ``pairwise``."""
    if name == KLT_SECTOR:
        return KLT_SECTOR
    return "familiarity" if is_memory_method(name) else "pairwise"


def _method_problem(k: int, entry: MethodEntry) -> str:
    """Why a route run cannot home with ``entry``, its ``k``-th method entry, naming the key
    ("" when it can)."""
    if entry.method == KLT_SECTOR:
        if entry.params or entry.grid or entry.compass != "none":
            return (
                f"methods.{k}: klt-sector homes with its own route homing, set by 'tracker' and "
                "'homing'; its entry takes no params, grid or compass"
            )
        return ""
    return robot_entry_error(k, entry, robot="route")


def load_route_config(path: Path, overrides: Sequence[str] = ()) -> RouteConfig:
    """Read and validate a route config with ``key.path=value`` ``overrides``; problems are
    ConfigErrors naming file and key."""
    return route_config(read_yaml(path, "config", overrides))


def route_config(document: YamlDocument) -> RouteConfig:
    """A route run's config from its YAML document (:func:`homebench.yamlio.read_yaml`)."""
    return validate(RouteConfig, document)
