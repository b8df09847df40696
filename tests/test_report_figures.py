"""Report figures: styles, the arrays behind the figures, and that every figure draws."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgb
from test_report_runs import GRID, FakeMethod, write_fake_run

from homebench.config import MetricsConfig
from homebench.evaluation.results import build_tables
from homebench.report.figure_data import (
    condition_goals,
    goal_panels,
    image_describe_times,
    pick_goals,
)
from homebench.report.grid_figures import ae_figure, field_figure, shared_ae_scale
from homebench.report.metric_figures import MAX_RR_BARS, ahc_figure, rr_figure, timing_figure
from homebench.report.route_figures import RouteResult, route_error_figure, route_figure
from homebench.report.style import PALETTE, PINNED, method_styles, report_style, save_png

HOLES = frozenset({(0, 0), (3, 4)})
METHODS = [
    FakeMethod("perfect", 0.0),
    FakeMethod("reversed", 180.0),
    FakeMethod("holes", 30.0, HOLES, home_ms=5.0, describe_ms=0.5),
]


@pytest.fixture(scope="module")
def tables(tmp_path_factory: pytest.TempPathFactory):
    run = write_fake_run(tmp_path_factory.mktemp("run"), METHODS, conditions=("a-a", "a-b"))
    return build_tables(run, MetricsConfig())


def _image(path: Path) -> np.ndarray:
    """The PNG as RGB, checked to be a real picture (large, not blank)."""
    bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
    assert bgr is not None, path
    assert bgr.shape[0] > 300 and bgr.shape[1] > 500
    assert bgr.std() > 10
    return bgr[..., ::-1]


def _pixels_of(image: np.ndarray, colour: str) -> int:
    rgb = np.round(np.array(to_rgb(colour)) * 255)
    return int(np.sum(np.all(np.abs(image.astype(int) - rgb) <= 2, axis=-1)))


def _save(fig, path: Path) -> np.ndarray:
    save_png(fig, path)
    return _image(path)


def test_pinned_methods_keep_their_style_whatever_else_is_drawn() -> None:
    alone = method_styles(["warping"])
    crowd = method_styles(["zeta", "alpha", "warping", "sift", "klt-sector", "min-warping"])
    assert alone["warping"] == crowd["warping"]
    for label, (colour, _) in PINNED.items():
        assert crowd[label].colour == PALETTE[colour]
    # the others share none of the pinned colours, and order of the input does not matter
    pinned = {PALETTE[c] for c, _ in PINNED.values()}
    assert {crowd["alpha"].colour, crowd["zeta"].colour}.isdisjoint(pinned)
    assert crowd == method_styles(reversed(list(crowd)))
    many = method_styles([f"m{k}" for k in range(30)])
    assert len({(s.colour, s.marker, s.linestyle) for s in many.values()}) == 30


def test_goal_panels_mark_failures_and_missing_estimates(tables) -> None:
    panels = {p.label: p for p in goal_panels(tables.pairs, MetricsConfig(), "a-a", (1, 2))}
    assert list(panels) == ["holes", "perfect", "reversed"]
    tested = np.ones(GRID.shape, dtype=bool)
    tested[1, 2] = False
    for panel in panels.values():
        assert np.array_equal(panel.tested, tested)
    assert not panels["perfect"].rr_failed.any() and panels["perfect"].rr == 1.0
    # reversed: every start but the goal walks away
    assert np.array_equal(panels["reversed"].rr_failed, tested)
    assert panels["reversed"].rr == pytest.approx(1 / GRID.size)
    holes = panels["holes"]
    assert sorted(zip(*np.nonzero(holes.no_estimate), strict=True)) == sorted(HOLES)
    assert np.allclose(holes.ae_deg[tested & ~holes.no_estimate], 30.0)
    assert holes.mean_ae_deg == pytest.approx(30.0)
    assert panels["reversed"].mean_ae_deg == pytest.approx(180.0)


def test_pick_goals_spreads_over_the_list() -> None:
    goals = [(i, 0) for i in range(10)]
    assert pick_goals(goals, 3) == [(0, 0), (4, 0), (9, 0)]
    assert pick_goals(goals, 4) == [(0, 0), (3, 0), (6, 0), (9, 0)]
    assert pick_goals(goals, 20) == goals
    assert pick_goals(goals, 1) == [(0, 0)]


def test_describe_times_count_each_image_once(tables) -> None:
    for condition, n_images in (("a-a", GRID.size), ("a-b", GRID.size + 2)):
        pairs = tables.pairs[tables.pairs["condition"] == condition]
        times = image_describe_times(pairs)
        assert (times.groupby("method").size() == n_images).all()
    assert condition_goals(tables.pairs, "a-b") == [(1, 2), (2, 3)]


def test_shared_ae_scale_covers_the_largest_error(tables) -> None:
    panels = goal_panels(tables.pairs, MetricsConfig(), "a-a", (1, 2))
    assert shared_ae_scale(panels) == 180.0
    holes = [p for p in panels if p.label == "holes"]
    assert shared_ae_scale(holes) == 30.0


def test_field_arrows_take_the_method_colour_only_where_homing_succeeds(
    tables, tmp_path: Path
) -> None:
    styles = method_styles(["holes", "perfect", "reversed"])
    panels = {p.label: p for p in goal_panels(tables.pairs, MetricsConfig(), "a-a", (1, 2))}
    with report_style():
        good = _save(field_figure([panels["perfect"]], styles, "t"), tmp_path / "good.png")
        bad = _save(field_figure([panels["reversed"]], styles, "t"), tmp_path / "bad.png")
        both = _save(field_figure(list(panels.values()), styles, "t"), tmp_path / "all.png")
    assert _pixels_of(good, styles["perfect"].colour) > 500
    assert _pixels_of(bad, styles["reversed"].colour) == 0
    assert _pixels_of(both, styles["holes"].colour) > 500


def test_ae_map_uses_one_scale(tables, tmp_path: Path) -> None:
    panels = goal_panels(tables.pairs, MetricsConfig(), "a-b", (2, 3))
    with report_style():
        fig = ae_figure(panels, "AE")
        meshes = [c for ax in fig.axes[:3] for c in ax.collections if isinstance(c, QuadMesh)]
        assert len(meshes) == 3
        assert {m.get_clim() for m in meshes} == {(0.0, 180.0)}
        _save(fig, tmp_path / "ae.png")


def test_metric_figures_draw(tables, tmp_path: Path) -> None:
    styles = method_styles(["holes", "perfect", "reversed"])
    many_goals = tables.goals.copy()
    many_goals = many_goals.loc[np.repeat(many_goals.index, MAX_RR_BARS)].reset_index(drop=True)
    many_goals["goal_i"] = np.arange(len(many_goals))
    many_goals["rr"] = np.linspace(0.0, 1.0, len(many_goals))
    pairs = tables.pairs[tables.pairs["condition"] == "a-a"]
    spread = np.tile(np.linspace(0.5, 2.0, 19), len(pairs) // 19)  # times of each job vary
    pairs = pairs.assign(
        home_ms=pairs["home_ms"] * spread, describe_ms=pairs["describe_ms"] * spread
    )
    with report_style():
        figures = {
            "ahc": ahc_figure(tables.ahc[tables.ahc["condition"] == "a-a"], styles, "AHC"),
            "rr": rr_figure(tables.goals[tables.goals["condition"] == "a-a"], styles, "RR"),
            "rr_boxes": rr_figure(many_goals, styles, "RR of many goals"),
            "timing": timing_figure(image_describe_times(pairs), pairs, styles, "time"),
        }
        for name, fig in figures.items():
            image = _save(fig, tmp_path / f"{name}.png")
            assert _pixels_of(image, styles["holes"].colour) > 50, name
    assert figures["ahc"].axes[0].get_ylim()[0] < -1.0  # the reversed method's AHC is visible
    timing_axes = figures["timing"].axes
    assert all(ax.get_yscale() == "log" for ax in timing_axes)
    ticks = [t.get_text() for t in timing_axes[1].get_xticklabels()]
    assert ticks[0] == f"holes\nmedian {5.0 * np.median(spread):.3g} ms"


def _route(label: str, length: float, miss: float, drift: float) -> RouteResult:
    t = np.linspace(0.0, 1.0, 21)
    outbound = np.stack([length * t, np.zeros_like(t), np.zeros_like(t)], axis=1)
    homing = outbound[::-1].copy()
    homing[-1, 1] = miss
    odometry = outbound[::-1].copy()
    odometry[:, 1] = drift * t
    return RouteResult(label, outbound, homing, [15, 10, 5], odometry)


def test_route_result_measures_route_and_errors() -> None:
    result = _route("klt-sector", 2.0, 0.03, 0.5)
    assert result.route_length_m == pytest.approx(2.0)
    assert result.final_error_m == pytest.approx(0.03)
    assert result.odometry_error_m == pytest.approx(0.5)
    with pytest.raises(ValueError, match="shape"):
        RouteResult("x", np.zeros((4, 2)), np.zeros((3, 3)), [], np.zeros((3, 3)))
    with pytest.raises(ValueError, match="intermediate"):
        RouteResult("x", np.zeros((4, 3)), np.zeros((3, 3)), [4], np.zeros((3, 3)))


def test_route_figures_draw(tmp_path: Path) -> None:
    results = [
        _route(label, length, miss, 0.1 * length)
        for label, miss in (("klt-sector", 0.004), ("sift", 0.05))
        for length in (1.0, 3.0)
    ]
    styles = method_styles(["klt-sector", "sift"])
    with report_style():
        trajectories = _save(route_figure(results[:2], styles, "route"), tmp_path / "route.png")
        errors_fig = route_error_figure(results, styles, "errors")
        errors = _save(errors_fig, tmp_path / "errors.png")
    assert _pixels_of(trajectories, styles["klt-sector"].colour) > 100
    assert _pixels_of(errors, styles["sift"].colour) > 50
    lines = {line.get_label(): line for line in errors_fig.axes[0].get_lines()}
    assert np.allclose(lines["sift"].get_xdata(), [1.0, 3.0])
    assert np.allclose(lines["sift"].get_ydata(), [0.05, 0.05])
    assert np.allclose(lines["odometry"].get_ydata(), [0.1, 0.3])
    assert math.isclose(lines["klt-sector"].get_ydata()[0], 0.004)
