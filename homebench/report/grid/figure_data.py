"""From a run's per-pair table to the plain arrays the figures draw."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from homebench.analysis.metrics import HomeField
from homebench.analysis.return_ratio import configured_return_ratio
from homebench.analysis.tables import goal_fields
from homebench.config import MetricsConfig
from homebench.geometry import FloatArray

BoolArray = NDArray[np.bool_]
T = TypeVar("T")


@dataclass(frozen=True, eq=False)
class GoalPanel:
    """One method's results towards one goal; arrays have the grid's shape (nx, ny).

    ``field``: world-frame home directions (radians), NaN where untested or no estimate.
    ``tested``: positions with a pair. ``ae_deg``: AE in degrees, NaN where untested or no
    estimate. ``rr``: the goal's return ratio, NaN when the field does not cover the grid (then
    ``rr_failed`` is all False). ``rr_failed``: the return-ratio trial from here fails.
    """

    label: str
    field: HomeField
    tested: BoolArray
    ae_deg: FloatArray
    rr: float
    rr_failed: BoolArray

    @property
    def no_estimate(self) -> BoolArray:
        return self.tested & np.isnan(self.field.angles)

    @property
    def mean_ae_deg(self) -> float:
        valid = self.ae_deg[~np.isnan(self.ae_deg)]
        return float(np.mean(valid)) if valid.size else float("nan")


@dataclass(frozen=True, order=True)
class Goal:
    """A goal of a run: grid index (``i``, ``j``) in the swept world (``style``, ``seed``);
    ``style`` "" and ``seed`` -1 without a sweep."""

    style: str
    seed: int
    i: int
    j: int

    @property
    def text(self) -> str:
        """The goal as text: "(i, j)", plus the world when swept: "(i, j) office seed 2"."""
        world = " ".join(
            [
                *([self.style] if self.style else []),
                *([f"seed {self.seed}"] if self.seed >= 0 else []),
            ]
        )
        return f"({self.i}, {self.j})" + (f" {world}" if world else "")

    def rows(self, frame: pd.DataFrame) -> pd.Series:
        """Which rows of ``frame`` (columns style, seed, goal_i, goal_j) are this goal's."""
        return (
            (_styles(frame) == self.style)
            & (_seeds(frame) == self.seed)
            & (frame["goal_i"] == self.i)
            & (frame["goal_j"] == self.j)
        )


def _styles(frame: pd.DataFrame) -> pd.Series:
    return frame["style"].astype(object).where(frame["style"].notna(), "").astype(str)


def _seeds(frame: pd.DataFrame) -> pd.Series:
    return frame["seed"].astype("Float64").fillna(-1).astype(int)


def goals_of(frame: pd.DataFrame) -> list[Goal]:
    """The goal of each row of ``frame`` (columns style, seed, goal_i, goal_j), in row order."""
    return [
        Goal(style, int(seed), int(i), int(j))
        for style, seed, i, j in zip(
            _styles(frame), _seeds(frame), frame["goal_i"], frame["goal_j"], strict=True
        )
    ]


def _grid_array(group: pd.DataFrame, shape: tuple[int, int], column: str) -> FloatArray:
    values = np.full(shape, np.nan)
    values[group["current_i"].to_numpy(), group["current_j"].to_numpy()] = (
        group[column].astype(float).to_numpy()
    )
    return values


def goal_panels(
    pairs: pd.DataFrame,
    metrics: MetricsConfig,
    condition: str,
    goal: Goal,
    methods: Sequence[str] = (),
) -> list[GoalPanel]:
    """One panel per method for ``goal`` under ``condition``: in the order of ``methods``,
    labels it does not list last (sorted)."""
    chosen = pairs[(pairs["condition"] == condition) & goal.rows(pairs)]
    panels = []
    for (_, _, _, method, _, _), field, complete in goal_fields(chosen):
        group = chosen[chosen["method"] == method]
        tested = ~np.isnan(_grid_array(group, field.grid.shape, "current_i"))
        failed = np.zeros(field.grid.shape, dtype=bool)
        rr = float("nan")
        if complete:
            result = configured_return_ratio(field, metrics.return_ratio)
            rr, failed = result.rr, result.started & ~result.success
        ae = _grid_array(group, field.grid.shape, "ae_deg")
        panels.append(GoalPanel(method, field, tested, ae, rr, failed))
    rank = {label: k for k, label in enumerate(methods)}
    return sorted(panels, key=lambda panel: (rank.get(panel.label, len(rank)), panel.label))


def pick_goals(goals: Sequence[T], limit: int | None) -> list[T]:
    """At most ``limit`` of ``goals`` (kept in order), spread evenly over the list; all of
    them when ``limit`` is None."""
    if limit is None or len(goals) <= limit:
        return list(goals)
    index = np.unique(np.round(np.linspace(0, len(goals) - 1, limit)).astype(int))
    return [goals[k] for k in index]


def pages(items: Sequence[T], per_page: int) -> list[list[T]]:
    """``items`` in order, cut into ``ceil(len / per_page)`` runs of at most ``per_page``."""
    count = math.ceil(len(items) / per_page)
    return [list(items[k * per_page : (k + 1) * per_page]) for k in range(count)]


def condition_goals(pairs: pd.DataFrame, condition: str) -> list[Goal]:
    """The goals with results under ``condition``, sorted (by world, then index)."""
    chosen = pairs[pairs["condition"] == condition]
    return sorted(set(goals_of(chosen)))


def image_describe_times(pairs: pd.DataFrame) -> pd.DataFrame:
    """Describe time per image (ms): columns method, describe_ms; each image counts once.

    An image is (method, database alias, i, j, rotation), as its feature file: a current image
    repeats in every goal's rows, a goal in all its rows, and under a condition like
    ``a-a`` a goal is also a current image of the other goals.
    """
    aliases = pairs["condition"].str.split("-", n=1, expand=True)
    current = pd.DataFrame({
        "method": pairs["method"], "database": aliases[0], "i": pairs["current_i"],
        "j": pairs["current_j"], "rotation": pairs["rotation"].astype(float),
        "describe_ms": pairs["describe_ms"],
    })  # fmt: skip
    goal = pd.DataFrame({
        "method": pairs["method"], "database": aliases[1], "i": pairs["goal_i"],
        "j": pairs["goal_j"], "rotation": 0.0, "describe_ms": pairs["goal_describe_ms"],
    })  # fmt: skip
    images = pd.concat([current, goal], ignore_index=True)
    unique = images.drop_duplicates(["method", "database", "i", "j", "rotation"])
    return unique[["method", "describe_ms"]].reset_index(drop=True)
