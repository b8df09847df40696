"""One thread per numeric library inside homebench's own calls, in any process.

numpy's BLAS (OpenBLAS, MKL, ...) and OpenMP start a thread per core unless the environment
says otherwise. homebench's calls are small (0.1 to a few ms), and spread over threads they cost
more than they save: twice the CPU on an idle 2-core host (threads spin while they wait), up
to 30 times on a busy one (issue 38). A run's job workers set the thread variables before
numpy loads (:data:`homebench.evaluation.isolation.THREAD_LIMITS`); a user's own script,
notebook or plugin test does not. So every registered method's calls (:data:`CALLS`) run
:func:`single_threaded`: the loaded libraries are set to one thread while the call runs
(threadpoolctl) and given back what they had when it ends, so that the user's own code outside
homebench's calls keeps the user's settings.

Cost: 13-16 microseconds of CPU a call where libraries had more than one thread (three
OpenBLAS copies: numpy's, OpenCV's, scipy's), 5 where none had (the job workers); calls within
a call (a method's ``home`` through its ``home_many``, the pairs of
:func:`~homebench.methods.base.home_many`) pay a counter, 1 microsecond. The libraries are found
once and again only after modules were imported (a new module may have loaded one): finding
them takes 0.5 ms.

Calls from several threads share one limit, the libraries' settings being process-wide: the
first call to start sets it, the last to end restores it (a thread that holds a threadpoolctl
limit of its own meanwhile keeps OpenBLAS to it: threadpoolctl lets one thread set it at a
time). OpenCV's own threads are left alone: on these calls they cost no CPU (wall time up to
1.2 x a single thread's for some describes on a busy host, ``benchmarks/bench_threads.py``), and
turning them off and on would make the caller's next parallel OpenCV call start its threads
again (1.5 ms). homebench's numba kernels are not ``parallel``: numba starts no threads of its
own (NUMBA_NUM_THREADS plays no part).
"""

from __future__ import annotations

import functools
import inspect
import sys
import threading
from collections.abc import Callable
from typing import Any, TypeVar

from threadpoolctl import LibController, OpenBLASController, ThreadpoolController

F = TypeVar("F", bound=Callable[..., Any])

#: The calls of a method class that run with one thread: its protocol
#: (:class:`~homebench.methods.base.HomingMethod`, ``home_many``, ``describe_route``) and the
#: route-memory protocol (:mod:`~homebench.methods.familiarity.route_memory`).
CALLS = ("describe", "describe_route", "home", "home_many", "learn", "unfamiliarity", "follow")

_LOCK = threading.Lock()
_depth = 0  # calls running (all threads)
_restore: list[tuple[LibController, int]] = []  # what the outermost call changed
_found: tuple[int, list[LibController]] = (-1, [])  # (len(sys.modules), libraries) when found


def _libraries() -> list[LibController]:
    """The thread-pool libraries loaded now, found again only when modules were imported."""
    global _found
    modules = len(sys.modules)
    if modules != _found[0]:
        _found = (modules, ThreadpoolController().lib_controllers)
    return _found[1]


def _set(changes: list[tuple[LibController, int]]) -> None:
    """Set each library's threads, then let go of OpenBLAS (threadpoolctl lets one thread at a
    time set it: the one that set it, until it lets go), so that any thread may restore it."""
    for library, threads in changes:
        library.set_num_threads(threads)
    OpenBLASController.clear_controlling_thread()


def _enter() -> None:
    global _depth, _restore
    with _LOCK:
        if _depth == 0:
            counts = [(library, library.get_num_threads()) for library in _libraries()]
            _restore = [(library, n) for library, n in counts if n is not None and n > 1]
            if _restore:
                _set([(library, 1) for library, _ in _restore])
        _depth += 1


def _leave() -> None:
    global _depth, _restore
    with _LOCK:
        _depth -= 1
        if _depth == 0 and _restore:
            _set(_restore)
            _restore = []


def single_threaded(function: F) -> F:
    """``function`` run with every loaded BLAS / OpenMP library on one thread, each given
    back what it had when the outermost such call ends."""

    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        _enter()
        try:
            return function(*args, **kwargs)
        finally:
            _leave()

    call.single_threaded = True  # type: ignore[attr-defined]
    return call  # type: ignore[return-value]


def limit_calls(cls: type) -> None:
    """Make the :data:`CALLS` a method class has (its own or inherited) single-threaded, on
    the class itself; calls already made so (a registered base class's) are left as they are."""
    for name in CALLS:
        owner = next((c for c in cls.__mro__ if name in c.__dict__), None)
        function = None if owner is None else owner.__dict__[name]
        if inspect.isfunction(function) and not getattr(function, "single_threaded", False):
            setattr(cls, name, single_threaded(function))
