"""What a homing method is: views in, features out, two features in, an estimate out.

Methods are pure: they know nothing of files, configs or jobs. :class:`View` and
:data:`ImageKind` live in :mod:`homebench.views` (the data and imaging layers hold views too)
and are re-exported here, the interface a method author reads. A method is a frozen dataclass
whose fields are its parameters (with the papers' defaults), registered under a name with
:func:`homebench.methods.registry.register`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal, Protocol, runtime_checkable

import numpy as np

from homebench.methods.threads import single_threaded
from homebench.views import ImageKind, View

__all__ = ["HomingEstimate", "HomingMethod", "ImageKind", "RouteShape", "View"]

#: How the engine lays routes out over a grid for methods that track along them
#: (:mod:`homebench.evaluation.grid_routes`).
RouteShape = Literal["tree", "line"]

#: Relative spread below which a signal counts as texture-less.
FLAT_TOLERANCE = 1e-9


def is_flat(signal: np.ndarray) -> bool:
    """True when ``signal`` (any shape) has no texture to match (spread ~ 0): the test every
    method makes before it matches, here so that no method's code version follows another's."""
    high, low = float(signal.max()), float(signal.min())
    return high - low <= FLAT_TOLERANCE * (1.0 + max(high, -low))


@dataclass(frozen=True)
class HomingEstimate:
    """A method's answer for one (current, goal) pair.

    ``angle``: home direction in the current robot frame (radians, ccw, 0 = heading), or None
    when the method cannot decide. ``rotation``: estimated heading change from goal to current
    (radians, ccw), or None. ``n_landmarks``: correspondences or features the estimate rests on.
    """

    angle: float | None
    rotation: float | None = None
    n_landmarks: int = 0
    score: float | None = None
    diagnostics: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def none(cls, n_landmarks: int = 0, **diagnostics: Any) -> HomingEstimate:
        """The explicit "no estimate" result (too few landmarks, no texture, ...)."""
        return cls(angle=None, rotation=None, n_landmarks=n_landmarks, diagnostics=diagnostics)


@runtime_checkable
class HomingMethod(Protocol):
    """The interface every registered method implements.

    A method that tracks features along the way from the goal (KLT-sector) sets the class
    attribute ``uses_route = True``, a ``route_step`` field (grid units) and optionally a
    ``route_shape`` (:data:`RouteShape`, default ``line``);
    its ``home`` then takes ``route=``, the features of the intermediate views from the goal
    towards the current view, which the engine supplies, described by the method's
    ``describe_route(view)`` where it has one (else ``describe``).

    A method that gives no home direction, only a heading change (a visual compass), sets
    the class attribute ``gives_direction = False``: its pairs then have no direction metric
    (AE, AHC, RR, catchment: n/a everywhere), only its rotation error.

    Registering a method (:func:`~homebench.methods.registry.register`) makes these calls,
    ``home_many``, ``describe_route`` and the route-memory ones run with one BLAS / OpenMP
    thread in any process, the caller's settings given back after each
    (:mod:`~homebench.methods.threads`).

    A method whose module imports heavy modules only when they first run (compiled numba
    kernels: importing numba costs a third of a second of CPU) names them in the class
    attribute ``preload_modules`` (a tuple of module names); the worker server of a run with
    the method imports them once, before it forks the workers.

    A method may also answer many current views of one goal at once (optional, see
    :data:`BatchHome`): ``home_many(currents, goal, **extra)``, where a job's pairs share
    what depends on the goal alone, or one large array operation replaces many small ones.
    Its estimates must be those of ``home`` pair by pair, bit for bit; if it raises, the engine
    asks ``home`` pair by pair, so only a failing pair fails. Without it, the engine calls
    ``home`` per pair (:func:`home_many` says so for any method).
    """

    name: ClassVar[str]
    image_kind: ClassVar[ImageKind]

    def describe(self, view: View) -> Any:
        """Per-image features, stored in feature files: see
        :mod:`homebench.evaluation.features_io` for the types they may hold."""
        ...

    def home(self, current: Any, goal: Any) -> HomingEstimate:
        """Home direction at the current view towards the goal view, from their features."""
        ...


#: ``home_many(currents, goal, **extra)``: the estimates (one per current, in order) of the
#: current views' features ``currents`` (a sequence of n) towards one goal's; each ``extra``
#: keyword is a sequence of n, the pair's own argument of ``home`` (``route=``, ...).
BatchHome = Callable[..., list[HomingEstimate]]


def batch_home(method: Any) -> BatchHome | None:
    """The method's own ``home_many`` (:class:`HomingMethod`), or None when it has none."""
    return getattr(method, "home_many", None)


@single_threaded  # once for the batch: the calls within pay a counter, not the limit's cost
def home_many(
    method: Any, currents: Sequence[Any], goal: Any, **extra: Sequence[Any]
) -> list[HomingEstimate]:
    """The estimates of ``method`` for the pairs of ``currents`` (n features) and one ``goal``:
    its ``home_many`` where it has one, else ``home`` pair by pair (``extra``: keyword
    arguments of ``home``, one sequence of n per keyword)."""
    batch = batch_home(method)
    if batch is not None:
        return batch(currents, goal, **extra)
    return [
        method.home(current, goal, **{name: values[k] for name, values in extra.items()})
        for k, current in enumerate(currents)
    ]


def gives_direction(method: type) -> bool:
    """Whether the method class answers home directions (``gives_direction``, default True)."""
    return bool(getattr(method, "gives_direction", True))


def checked_estimate(answer: Any, call: str = "home") -> HomingEstimate:
    """``answer`` of a method's ``call`` ("home", "home_many") if it is a
    :class:`HomingEstimate` whose angle and rotation are finite numbers (radians) or None;
    TypeError naming what it is otherwise ("home_many answered a str, not a
    HomingEstimate"), ValueError for an angle or rotation that is no finite number."""
    if not isinstance(answer, HomingEstimate):
        raise TypeError(f"{call} answered a {type(answer).__name__}, not a HomingEstimate")
    for name in ("angle", "rotation"):
        value = getattr(answer, name)
        if value is None:
            continue
        try:
            number = None if isinstance(value, str | bytes) else float(value)
        except (TypeError, ValueError):
            number = None
        if number is None:
            raise TypeError(f"{call} answered a {type(value).__name__} {name}, not a number")
        if not math.isfinite(number):
            raise ValueError(f"{call} answered {name} {number}, not a finite number of radians")
    return answer
