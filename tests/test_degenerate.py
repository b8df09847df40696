"""Degenerate views for every registered method: no texture, identical views, a corner goal.

Each method must return "no estimate" (angle None) or a correct answer — never NaN, never an
exception — and the tables must count what has no estimate.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import run_config

from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import render_position
from homebench.methods import registry
from homebench.methods.base import HomingEstimate, View

SPEC = WorldSpec(grid={"shape": [3, 3]})
#: Methods that give home directions (the visual compass gives rotations only).
HOMING = [
    "warping",
    "min-warping",
    "sift",
    "sift-unfolded",
    "klt-sector",
    "mfdid",
    "did",
    "alv",
    "snapshot",
    "warping-2d",
    "fourier-warping",
    "block-matching",
]
BUILT_IN = [*HOMING, "visual-compass", "perfect-memory", "infomax"]


def _view(kind: str, image: np.ndarray) -> View:
    geometry = SPEC.raw.geometry() if kind == "raw" else SPEC.unfolded.geometry()
    return View(image, geometry)


def _home(name: str, current: View, goal: View) -> HomingEstimate:
    method = registry.create(name)
    return method.home(method.describe(current), method.describe(goal))


def _assert_no_nan(estimate: HomingEstimate) -> None:
    """Every number of ``estimate`` is finite or None: its angle, rotation and score, its
    landmark count and the numbers among its diagnostics."""
    diagnostics = {k: v for k, v in estimate.diagnostics.items() if isinstance(v, float | int)}
    numbers = {"angle": estimate.angle, "rotation": estimate.rotation, "score": estimate.score}
    for name, value in {**numbers, **diagnostics}.items():
        assert value is None or math.isfinite(value), (name, value)
    assert isinstance(estimate.n_landmarks, int) and estimate.n_landmarks >= 0


@pytest.mark.parametrize(
    "estimate",
    [
        HomingEstimate(None, score=math.nan),
        HomingEstimate(0.5, rotation=math.inf),
        HomingEstimate(None, diagnostics={"psi": math.nan}),
        HomingEstimate(None, n_landmarks=-1),
    ],
)
def test_the_estimate_check_catches_a_nan(estimate: HomingEstimate) -> None:
    with pytest.raises(AssertionError):
        _assert_no_nan(estimate)


@pytest.mark.parametrize("name", BUILT_IN)
def test_texture_less_views_give_no_estimate(name: str) -> None:
    kind = registry.get(name).image_kind
    shape = (SPEC.raw.height, SPEC.raw.width) if kind == "raw" else (
        SPEC.unfolded.height, SPEC.unfolded.width
    )  # fmt: skip
    flat = _view(kind, np.full(shape, 97, np.uint8))
    estimate = _home(name, flat, flat)
    _assert_no_nan(estimate)
    assert estimate.angle is None


@pytest.mark.parametrize("name", BUILT_IN)
def test_identical_views_give_no_direction_or_no_turn(name: str) -> None:
    kind = registry.get(name).image_kind
    view = _view(kind, render_position(SPEC, 1, 1)[kind])
    estimate = _home(name, view, view)
    _assert_no_nan(estimate)
    # at the goal there is no home direction (any answer would be arbitrary); a method that
    # reports a rotation must see no turn
    assert estimate.angle is None
    assert estimate.rotation is None or abs(estimate.rotation) < 0.02


def test_all_methods_at_a_corner_goal_fill_the_tables(tmp_path: Path) -> None:
    config = {
        "output": str(tmp_path / "run"),
        "databases": {"room": {"world": SPEC.model_dump(mode="json")}},
        "conditions": ["room-room"],
        "goals": [[0, 0], [2, 2]],
        "methods": [{"method": name} for name in HOMING],
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    tables = tmp_path / "run" / "tables"
    pairs = pd.read_csv(tables / "pairs.csv")
    assert len(pairs) == len(HOMING) * 2 * 8
    answered = pairs["estimate_rad"].notna()
    assert np.isfinite(pairs.loc[answered, "ae_rad"]).all()
    assert pairs.loc[~answered, "ae_rad"].isna().all()  # no estimate: no AE, counted below
    summary = pd.read_csv(tables / "summary.csv").set_index("method")
    share = pairs.groupby("method")["estimate_rad"].apply(lambda s: s.isna().mean())
    pd.testing.assert_series_equal(
        summary["no_estimate_share"].sort_index().astype(float),
        share.sort_index(),
        check_names=False,
    )
    _assert_empty_only_where_nothing_was_measured(tables)


#: Columns of pairs.csv that a pair without an estimate leaves empty, and those a method may
#: leave empty beside an estimate (no rotation or no score reported).
_ANSWER = ("estimate", "estimate_world", "ae", "rotation_estimate", "rotation_error")
#: times: empty for a worker's first call of a method (it holds one-off costs, see
#: homebench.evaluation.pair_calls.timed)
_TIMES = {"home_ms", "describe_ms", "goal_describe_ms"}
_NO_ESTIMATE = {f"{name}_{unit}" for name in _ANSWER for unit in ("rad", "deg")} | {
    "score",
    "error",
    *_TIMES,
}
#: "error": empty unless the pair failed
_OPTIONAL = {
    f"{name}_{unit}" for name in ("rotation_estimate", "rotation_error") for unit in ("rad", "deg")
} | {"score", "error", *_TIMES}


#: How a non-finite number may be spelt in a CSV cell.
_NON_FINITE = {"nan", "inf", "-inf", "+inf", "infinity", "-infinity"}


def _assert_empty_only_where_nothing_was_measured(tables: Path) -> None:
    """pandas writes NaN as an empty field: an empty cell is a NaN that reached the table, and
    infinities are written out ("inf", "-inf").

    Allowed: the style and seed columns (a run that sweeps neither), and in pairs.csv the
    estimate's columns of pairs without an estimate. Every summary cell is filled (every method
    answered here).
    """
    for name in ("pairs.csv", "summary.csv"):
        cells = pd.read_csv(tables / name, dtype=str, keep_default_na=False)
        empty = (cells == "").drop(columns=["style", "seed"], errors="ignore")
        if name == "pairs.csv":
            unanswered = empty["estimate_rad"]
            allowed = empty.columns.isin(list(_NO_ESTIMATE))
            optional = empty.columns.isin(list(_OPTIONAL))
            stray = empty.loc[unanswered, ~allowed].any() | empty.loc[~unanswered, ~optional].any()
        else:
            # a method without rotations has no rotation error
            rotation = ("rotation_error", "rotation_flip")
            stray = empty.drop(columns=[c for c in empty if c.startswith(rotation)]).any()
        assert not stray.any(), f"{name}: empty cells in {list(stray[stray].index)}"
        spelled = cells.apply(lambda column: column.str.lower().isin(_NON_FINITE)).any()
        assert not spelled.any(), f"{name}: non-finite numbers in {list(spelled[spelled].index)}"


def test_the_table_check_catches_a_nan(tmp_path: Path) -> None:
    pairs = pd.DataFrame(
        {
            "seed": [None, None],
            "estimate_rad": [0.5, None],
            "ae_rad": [0.1, None],
            "truth_rad": [0.4, 1.0],
        }
    )
    summary = pd.DataFrame({"method": ["m"], "mean_ae_deg": [5.0]})
    pairs.to_csv(tmp_path / "pairs.csv", index=False)
    summary.to_csv(tmp_path / "summary.csv", index=False)
    _assert_empty_only_where_nothing_was_measured(tmp_path)  # a missing estimate is fine
    summary.assign(mean_ae_deg=[float("nan")]).to_csv(tmp_path / "summary.csv", index=False)
    with pytest.raises(AssertionError, match="summary.csv"):
        _assert_empty_only_where_nothing_was_measured(tmp_path)
    summary.assign(mean_ae_deg=[float("-inf")]).to_csv(tmp_path / "summary.csv", index=False)
    with pytest.raises(AssertionError, match="summary.csv: non-finite numbers in .'mean_ae_deg'"):
        _assert_empty_only_where_nothing_was_measured(tmp_path)
    summary.to_csv(tmp_path / "summary.csv", index=False)
    pairs.assign(truth_rad=[0.4, float("nan")]).to_csv(tmp_path / "pairs.csv", index=False)
    with pytest.raises(AssertionError, match="truth_rad"):
        _assert_empty_only_where_nothing_was_measured(tmp_path)
    pairs.assign(estimate_rad=[float("inf"), None]).to_csv(tmp_path / "pairs.csv", index=False)
    with pytest.raises(AssertionError, match="pairs.csv: non-finite numbers in .'estimate_rad'"):
        _assert_empty_only_where_nothing_was_measured(tmp_path)


def test_every_built_in_method_is_checked_here() -> None:
    builtins = {
        name
        for name, cls in registry.available().items()
        if cls.__module__.startswith("homebench.")
    }
    assert builtins == set(BUILT_IN)
