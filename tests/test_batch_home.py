"""Batch calls: a method's ``home_many`` gives ``home``'s estimates bit for bit, and the engine
homes a job's pairs through it (first pair alone, shares of the time, pair by pair on failure).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest
from synthetic_panorama import render

from homebench.evaluation import pair_calls
from homebench.evaluation.pair_calls import PairInput, home_pairs
from homebench.geometry import Pose
from homebench.methods import registry
from homebench.methods.base import HomingEstimate, batch_home, home_many
from homebench.methods.warping.method import Warping

#: Arena poses: a goal and currents around it, some turned.
GOAL = Pose(0.2, -0.3, 0.4)
CURRENTS = [Pose(GOAL.x + dx, GOAL.y + dy, h) for dx, dy, h in
            [(0.6, 0.0, 0.4), (0.0, -0.9, 1.5), (-1.2, 0.5, -2.0), (0.3, 0.3, 0.4),
             (0.0, 0.0, 0.4), (0.0, 0.0, 2.2), (-0.4, -1.1, 0.9), (1.1, 1.0, -0.3)]]  # fmt: skip


def _batched_builtins() -> list[str]:
    """The built-in methods that have a batch call."""
    found = [
        name
        for name, cls in registry.available().items()
        if cls.__module__.startswith("homebench.") and batch_home(cls) is not None
    ]
    assert "warping" in found
    return sorted(found)


@pytest.mark.parametrize("name", _batched_builtins())
def test_every_builtin_batch_call_gives_home_s_estimates_bit_for_bit(name):
    method = registry.create(name)
    assert method.image_kind == "unfolded", "add raw views to this test"
    goal = method.describe(render(GOAL))
    currents = [method.describe(render(pose)) for pose in CURRENTS]
    assert method.home_many(currents, goal) == [method.home(c, goal) for c in currents]


def _signals(seed: int, n: int, count: int) -> np.ndarray:
    """``count`` smooth random grey-level signals of n columns, shape (count, n)."""
    rng = np.random.default_rng(seed)
    spectrum = rng.normal(size=(count, n // 2 + 1)) + 1j * rng.normal(size=(count, n // 2 + 1))
    signals = np.fft.irfft(spectrum * np.exp(-np.arange(n // 2 + 1) / 4.0), n=n)
    return 128.0 + 60.0 * signals / signals.std(axis=1, keepdims=True)


@pytest.mark.parametrize(
    "params",
    [{}, {"distance": "dot"}, {"n_psi": 36}, {"n_columns": 48, "n_alpha": 12, "n_psi": 24}],
)
def test_warping_s_batch_is_home_pair_by_pair_whatever_the_block(params, monkeypatch):
    """Currents screened in blocks of one matrix product, blocks with a signal float32 cannot
    hold (searched exactly), texture-less signals, exact ties and the goal itself."""
    method = Warping(**params)
    n = method.n_columns
    goal, *signals = _signals(5, n, 30)
    flat = np.full(n, 80.0)
    tie = np.roll(np.tile(goal[: n // 2], 2), -3)  # ties between psi (period n/2) and at rho 0
    currents = [*signals[:12], flat, goal, tie, signals[12] * 1e30, *signals[13:]]
    expected = [method.home(c, goal) for c in currents]
    for block in (1, 3, 64):  # currents per matrix product
        monkeypatch.setattr(
            "homebench.methods.warping.search.SCREEN_BLOCK_BYTES",
            block * 4 * n * method.n_rho * method.n_alpha * n,
        )
        assert method.home_many(currents, goal) == expected
    assert method.home_many(currents, flat) == [method.home(c, flat) for c in currents]
    assert all(e.angle is None for e in method.home_many(currents, flat))
    assert method.home_many([], goal) == []


def test_the_protocol_s_default_homes_pair_by_pair():
    @dataclass(frozen=True)
    class Plain:
        name: ClassVar[str] = "plain"

        def home(self, current, goal, route=()):
            return HomingEstimate(angle=current - goal + len(route))

    assert batch_home(Plain()) is None
    estimates = home_many(Plain(), [1.0, 2.0], 0.5, route=[[], [0, 0]])
    assert [e.angle for e in estimates] == [0.5, 3.5]


@dataclass(frozen=True)
class Counting:
    """A method that answers ``current - goal`` (plus the route's length) and notes its calls;
    its batch call raises on a current of ``fail`` or answers one pair short if ``short``."""

    calls: list
    fail: float = math.nan
    short: bool = False

    def home(self, current, goal, route=()):
        self.calls.append(("home", current))
        if current == self.fail:
            raise ValueError("this pair fails")
        return HomingEstimate(angle=current - goal + len(route))

    def home_many(self, currents, goal, route):
        self.calls.append(("many", tuple(currents)))
        if self.fail in currents:
            raise ValueError("a batch with a failing pair")
        answers = [
            HomingEstimate(angle=c - goal + len(r)) for c, r in zip(currents, route, strict=True)
        ]
        return answers[:-1] if self.short else answers


def _pairs(*currents: float) -> list[PairInput]:
    return [PairInput(c, {"route": [0] * int(c)}) for c in currents]


def test_the_first_pair_of_a_process_goes_alone_the_rest_share_one_call(monkeypatch):
    monkeypatch.setattr(pair_calls, "_CALLED", set())
    calls: list = []
    answers = home_pairs("k", Counting(calls), 0.5, _pairs(1.0, 2.0, 3.0))
    assert calls == [("home", 1.0), ("many", (2.0, 3.0))]
    assert [a.angle for a, _ in answers] == [1.5, 3.5, 5.5]
    (_, first), (_, second), (_, third) = answers
    assert math.isnan(first) and second == third >= 0.0  # one-off costs; then shares
    calls.clear()
    home_pairs("k", Counting(calls), 0.5, _pairs(1.0, 2.0))
    assert calls == [("many", (1.0, 2.0))]  # later jobs: all pairs in one call


@pytest.mark.parametrize("method", [{"fail": 2.0}, {"short": True}])
def test_a_failing_batch_is_made_again_pair_by_pair(method, monkeypatch):
    monkeypatch.setattr(pair_calls, "_CALLED", {("k", "home")})
    calls: list = []
    answers = home_pairs("k", Counting(calls, **method), 0.5, _pairs(1.0, 2.0, 3.0))
    assert calls[1:] == [("home", 1.0), ("home", 2.0), ("home", 3.0)]
    estimates = [a if isinstance(a, str) else a.angle for a, _ in answers]
    if "fail" in method:
        assert estimates == [1.5, "ValueError: this pair fails", 5.5]
    else:
        assert estimates == [1.5, 3.5, 5.5]
    assert all(ms >= 0.0 for a, ms in answers if not isinstance(a, str))


@dataclass(frozen=True)
class Strings:
    """A method whose batch call answers strings, one per pair; its ``home`` too with
    ``home_too``."""

    home_too: bool = False

    def home(self, current, goal):
        return "north" if self.home_too else HomingEstimate(angle=current - goal)

    def home_many(self, currents, goal):
        return ["north"] * len(currents)


def test_answers_that_are_no_estimates_are_refused_naming_their_type(monkeypatch):
    """They were taken as the pairs' errors ("north")."""
    monkeypatch.setattr(pair_calls, "_CALLED", {("k", "home")})
    pairs = [PairInput(1.0, {}), PairInput(2.0, {})]
    answers = home_pairs("k", Strings(), 0.5, pairs)
    assert [a.angle for a, _ in answers] == [0.5, 1.5]  # asked of home, pair by pair
    answers = home_pairs("k", Strings(home_too=True), 0.5, pairs)
    assert [a for a, _ in answers] == ["TypeError: home answered a str, not a HomingEstimate"] * 2
