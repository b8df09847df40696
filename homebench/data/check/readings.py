"""Which reading of a database the images support: where its poses put the images (a grid's
label order, the sense of a route's headings) and the way its azimuths grow, fitted together.

Each reading gives every pair a true home direction (the order puts the two images somewhere,
the headings turn the current one) and a homed estimate (the direction reads the columns);
:func:`~homebench.data.check.azimuth.fit_offset` tells how well one constant turn explains the
difference. A transposed grid mirrors every direction about x = y, and a mirrored direction
mirrors every azimuth: on a grid of one heading the two fit alike (residuals ``90 deg - 2
heading - c``, one constant), so the images cannot tell a transposed grid from mirrored
columns. Where two readings tie, the stated reading wins if it is one of them; otherwise, for
a grid (``tie_break``), the order changes where the database says its labels are in doubt (a
grid of BoB's Ant World tools, whose recorder transposes grids:
:mod:`homebench.data.grid_order`), else the direction, and the other is named as the
alternative; without a tie break a tie tells nothing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from homebench.data.check.azimuth import AzimuthFit, fit_offset
from homebench.data.check.pairs import NeighbourPair, Pair
from homebench.data.database import GridDatabase
from homebench.data.grid_order import (
    GRID_ORDERS,
    GridOrder,
    Index,
    position_of,
    position_shape,
    same_mapping,
)
from homebench.geometry import Direction, home_direction

FloatArray = NDArray[np.float64]

#: A verdict needs the best reading's mean AE below this (deg) ...
MAX_MEAN_AE_DEG = 30.0
#: ... readings this close to it (deg) fit as well; a mirror image's is about 90 worse ...
MIN_MARGIN_DEG = 20.0
#: ... and this many pairs with an estimate.
MIN_HOMED = 20


@dataclass(frozen=True)
class Reading:
    """The images read with ``key`` (``grid.order``, ``headings.direction``) set to ``value``
    and their azimuths growing ``direction``."""

    key: str
    value: str
    direction: Direction


@dataclass(frozen=True)
class Choice:
    """The reading the images support (None: they tell none), ``fits`` of every reading tried
    (the stated first), and ``alternative``: another reading that fits as well."""

    reading: Reading | None
    fits: dict[Reading, AzimuthFit]
    alternative: Reading | None = None


def order_truths(db: GridDatabase, pairs: Sequence[NeighbourPair]) -> dict[str, FloatArray]:
    """Each pair's true home direction (radians, the current image's frame, shape (n_pairs,))
    were the images' labels read in each order (orders that map the grid's labels alike
    once, under one name: the stated first, then BoB's recorder's where the labels are in
    doubt)."""
    labels = db.label_grid  # the labels' whole grid: a block cut from one maps through it
    shape = position_shape(db.grid_order, labels.shape)
    orders: list[GridOrder] = [db.grid_order]
    for order in sorted(GRID_ORDERS, key=lambda o: db.order_in_doubt and o != "bob-recorder"):
        if not any(same_mapping(order, seen, shape) for seen in orders):
            orders.append(order)
    headings = np.array([db.heading(*p.current) for p in pairs])
    truths: dict[str, FloatArray] = {}
    for order in orders:
        positions = position_shape(order, labels.shape)

        def where(ij: Index, order: GridOrder = order, positions: Index = positions) -> FloatArray:
            return labels.position(*position_of(order, db.label(*ij), positions))

        current = np.array([where(p.current) for p in pairs])
        goal = np.array([where(p.goal) for p in pairs])
        truths[order] = home_direction(current, goal, headings)
    return truths


def fit_readings(
    key: str,
    truths: Mapping[str, FloatArray],
    estimates: Mapping[Direction, FloatArray],
    pairs: Sequence[Pair],
) -> dict[Reading, AzimuthFit]:
    """Every value's truths (of ``key``) against every direction's estimates, in the order
    given."""
    return {
        Reading(key, value, direction): fit_offset(truth, estimate, pairs)
        for value, truth in truths.items()
        for direction, estimate in estimates.items()
    }


TieBreak = Literal["value", "direction"]


def choose(fits: dict[Reading, AzimuthFit], stated: Reading, tie_break: TieBreak | None) -> Choice:
    """The reading ``fits`` support; where two readings tie, ``tie_break`` says which of the
    stated value and the stated direction to change (None: neither, nothing is told; see the
    module docstring)."""
    good = as_good(fits)
    if not good:
        return Choice(None, fits)
    if stated in good:
        return Choice(stated, fits)
    if len(good) == 1:
        return Choice(good[0], fits)
    if tie_break is not None and len(good) == 2:
        first, second = good
        if first.value != second.value and first.direction != second.direction:
            keeps_direction = first if first.direction == stated.direction else second
            chosen = keeps_direction if tie_break == "value" else _other(good, keeps_direction)
            return Choice(chosen, fits, _other(good, chosen))
    return Choice(None, fits)


def as_good(fits: dict[Reading, AzimuthFit]) -> list[Reading]:
    """The readings that fit about as well as the best, where the best fits well enough for a
    verdict (with enough pairs homed); none where it does not."""
    best = min(fits.values(), key=lambda f: f.mean_ae)
    if best.n_homed < MIN_HOMED or math.degrees(best.mean_ae) > MAX_MEAN_AE_DEG:
        return []
    margin = math.radians(MIN_MARGIN_DEG)
    return [r for r, f in fits.items() if f.mean_ae < best.mean_ae + margin]


def _other(pair: list[Reading], one: Reading) -> Reading:
    return pair[1] if pair[0] == one else pair[0]
