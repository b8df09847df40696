"""The home calls of a job: each prepared pair's estimate and home time, in one batch call where
the method answers many pairs at once (``home_many``, see :mod:`homebench.methods.base`), else
pair by pair.

Times (``home_ms`` of a pair's row) are wall times of the calls, in ms:

- a pair homed alone has its call's time;
- the pairs of one batch call share its time evenly: each has the call's time over its pairs
  (what the method computes once per batch, a goal's part, is spread over them);
- a process's first call of a method's ``describe`` or ``home`` has none (NaN, see
  :func:`timed`): it holds one-off costs. A method with a batch call homes the first pair of
  its first job in a process alone, so that one pair, not a whole job, goes without a time.

A batch call that raises, or answers another number of estimates than it was given pairs, or
anything but estimates (:func:`~homebench.methods.base.checked_estimate`), is made again pair
by pair: only a pair that fails alone fails, with its error in its row; so does a pair whose
``home`` answers no estimate (a string, an infinite angle), the error naming what it answered.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from homebench.methods.base import HomingEstimate, batch_home, checked_estimate

T = TypeVar("T")

#: (method key, "describe" or "home") of the calls this process has made: see :func:`timed`.
_CALLED: set[tuple[str, str]] = set()


def timed(method_key: str, call_kind: str, call: Callable[[], T]) -> tuple[T, float]:
    """``call()`` and its wall time in ms, or NaN for the first call of a method's
    ``describe`` or ``home`` in a process: that one holds one-off costs (compiling kernels,
    importing lazily, first allocations), so the tables' times are the steady-state cost. The
    call is made once, whatever it costs: a method's answers never depend on being timed."""
    start = time.perf_counter()
    result = call()
    elapsed_ms = 1000.0 * (time.perf_counter() - start)
    if (method_key, call_kind) in _CALLED:
        return result, elapsed_ms
    _CALLED.add((method_key, call_kind))
    return result, math.nan


def describe_error(error: BaseException) -> str:
    """One line for an exception of a job, image or pair (out of memory said as such)."""
    if isinstance(error, MemoryError):  # numpy's is a subclass with a private name
        return f"out of memory (MemoryError: {error})"
    return "".join(traceback.format_exception_only(type(error), error)).strip()


@dataclass(frozen=True)
class PairInput:
    """What ``home`` takes for one pair beside the goal's features: the current view's
    ``features`` and the ``extra`` keyword arguments (``route``, ``neighbours``)."""

    features: Any
    extra: dict[str, Any]


#: A pair's answer: its estimate, or the error its call raised (one line); its home time (ms;
#: NaN where none was taken).
Answer = tuple[HomingEstimate | str, float]


def home_pairs(method_key: str, method: Any, goal: Any, pairs: Sequence[PairInput]) -> list[Answer]:
    """The answers of ``method`` (of key ``method_key``) for ``pairs`` towards ``goal``'s
    features, in order (see the module docstring)."""
    batch = batch_home(method)
    if batch is None:
        return [_alone(method_key, method, goal, pair) for pair in pairs]
    answers: list[Answer] = []
    if pairs and (method_key, "home") not in _CALLED:  # the one-off costs: one pair's call
        answers.append(_alone(method_key, method, goal, pairs[0]))
        pairs = pairs[1:]
    if not pairs:
        return answers
    extra = {name: [pair.extra[name] for pair in pairs] for name in pairs[0].extra}
    try:
        estimates, ms = timed(
            method_key, "home", lambda: batch([pair.features for pair in pairs], goal, **extra)
        )
        if len(estimates) != len(pairs):
            raise ValueError(f"home_many answered {len(estimates)} of {len(pairs)} pairs")
        estimates = [checked_estimate(estimate, "home_many") for estimate in estimates]
    except Exception:  # pair by pair: only a failing pair fails
        return answers + [_alone(method_key, method, goal, pair) for pair in pairs]
    share = ms / len(pairs)
    return answers + [(estimate, share) for estimate in estimates]


def _alone(method_key: str, method: Any, goal: Any, pair: PairInput) -> Answer:
    """One pair's answer by ``home``."""
    try:
        estimate, ms = timed(
            method_key, "home", lambda: method.home(pair.features, goal, **pair.extra)
        )
        return checked_estimate(estimate), ms
    except Exception as error:  # one failed pair; the job's other pairs go on
        return describe_error(error), math.nan
