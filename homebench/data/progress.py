"""Progress bars of the data layer (generating worlds, checking and verifying images): on
stderr, only when it is a terminal, and none within ``progress_bars(False)`` (``homebench run
--no-progress``). Long work whose progress a log should show too (generating a world) gives,
when stderr is no terminal, a line per :data:`LOG_STEP_PERCENT` % instead of a bar
(:class:`LogLines`)."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")

#: Whether the data layer shows its bars.
_BARS: ContextVar[bool] = ContextVar("homebench_data_bars", default=True)
#: A log's progress line comes each time the work reaches another this many percent.
LOG_STEP_PERCENT = 10
#: A bar over a database's images or rows appears once its work has taken this long (s):
#: small databases show none.
ITEM_BAR_DELAY_S = 2.0


@contextmanager
def progress_bars(enabled: bool) -> Iterator[None]:
    """Within the block, the data layer shows its bars (``enabled``, and only when stderr is a
    terminal) or none."""
    token = _BARS.set(enabled)
    try:
        yield
    finally:
        _BARS.reset(token)


class LogLines:
    """Progress as a log reads it: ``desc: 40 % (68 of 170 positions, 25 s)`` on stderr each
    time the work reaches another :data:`LOG_STEP_PERCENT` %; a bar's ``update`` and context."""

    def __init__(self, total: int, desc: str, unit: str) -> None:
        self.total, self.desc, self.unit = total, desc, unit
        self.done = self.steps = 0
        self.started = time.perf_counter()

    def update(self, n: int = 1) -> None:
        self.done += n
        percent = 100 * self.done // max(self.total, 1)
        if percent // LOG_STEP_PERCENT > self.steps:
            self.steps = percent // LOG_STEP_PERCENT
            seconds = time.perf_counter() - self.started
            print(f"{self.desc}: {percent} % ({self.done} of {self.total} {self.unit}s, "
                  f"{seconds:.0f} s)", file=sys.stderr, flush=True)  # fmt: skip

    def __enter__(self) -> LogLines:
        return self

    def __exit__(self, *exc: object) -> None:
        return None


def bar(
    total: int | None, desc: str, unit: str, delay_s: float = 0.0, log: bool = False
) -> tqdm | LogLines:
    """A bar over ``total`` ``unit`` (None: a count), shown after ``delay_s`` (see the module
    docstring); ``log``: lines instead where stderr is no terminal (:class:`LogLines`)."""
    if log and total and _BARS.get() and not sys.stderr.isatty():
        return LogLines(total, desc, unit)
    return tqdm(
        total=total,
        desc=desc,
        unit=unit,
        file=sys.stderr,
        delay=delay_s,
        disable=None if _BARS.get() else True,  # None: off unless stderr is a terminal
    )


def over(items: Iterable[T], total: int | None, desc: str, unit: str = "image") -> Iterator[T]:
    """``items`` (``total`` of them; None: not known) with a bar over them, once they take
    :data:`ITEM_BAR_DELAY_S`."""
    with bar(total, desc, unit, ITEM_BAR_DELAY_S) as shown:
        for item in items:
            yield item
            shown.update()
