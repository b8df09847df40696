"""Progress bars of the data layer (generating worlds, checking and verifying images): on
stderr, only when it is a terminal, and none within ``progress_bars(False)`` (``homebench run
--no-progress``)."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")

#: Whether the data layer shows its bars.
_BARS: ContextVar[bool] = ContextVar("homebench_data_bars", default=True)
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


def bar(total: int | None, desc: str, unit: str, delay_s: float = 0.0) -> tqdm:
    """A bar over ``total`` ``unit`` (None: a count), shown after ``delay_s`` (see the module
    docstring)."""
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
