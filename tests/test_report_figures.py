"""Report figures: styles, scales, layout, the arrays behind the figures, and file output."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.axis import Axis
from matplotlib.collections import PolyCollection, QuadMesh
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.quiver import Quiver
from matplotlib.text import Text
from test_report_runs import GRID, FakeMethod, write_fake_run

from homebench.config import MetricsConfig, ReturnRatioConfig
from homebench.evaluation.results import build_tables
from homebench.geometry import Grid
from homebench.report.grid.field_figures import (
    AE_MAX_DEG,
    MAX_GOALS_PER_FIGURE,
    TITLE_MIN_POINTS,
    ae_figure,
    field_figure,
    grid_layout,
    grid_pages,
    panel_title,
    text_width,
)
from homebench.report.grid.figure_data import (
    Goal,
    condition_goals,
    goal_panels,
    image_describe_times,
    pages,
    pick_goals,
)
from homebench.report.grid.metric_figures import (
    MAX_RR_BARS,
    ConditionPanel,
    RRPanel,
    ahc_bins,
    ahc_figure,
    ahc_range,
    rr_figure,
    timing_figure,
)
from homebench.report.grid.report import (
    _goal_figures,
    _metric_figures,
    _rr_walks,
    grid_figures,
    run_styles,
)
from homebench.report.route.figures import RouteResult, route_error_figure, route_figure
from homebench.report.run_data import load_run
from homebench.report.style import (
    DOUBLE_COLUMN,
    FREE_COLOURS,
    LINESTYLES,
    MARKERS,
    MAX_FIGURE_HEIGHT,
    PALETTE,
    PINNED,
    SINGLE_COLUMN,
    method_style,
    method_styles,
    report_style,
    save_figure,
)

HOLES = frozenset({(0, 0), (3, 4)})
METHODS = [
    FakeMethod("perfect", 0.0),
    FakeMethod("reversed", 180.0),
    FakeMethod("holes", 30.0, HOLES, home_ms=5.0, describe_ms=0.5),
]
LABELS = ["holes", "perfect", "reversed"]
#: Seven goals: more than one figure of fields holds.
MANY_GOALS = ((0, 0), (1, 2), (2, 3), (3, 4), (0, 4), (3, 0), (2, 1))


@pytest.fixture(scope="module")
def tables(tmp_path_factory: pytest.TempPathFactory):
    run = write_fake_run(tmp_path_factory.mktemp("run"), METHODS, conditions=("a-a", "a-b"))
    return build_tables(run, MetricsConfig())


@pytest.fixture(scope="module")
def many_goals_run(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("many")
    return load_run(write_fake_run(folder, METHODS, goals=MANY_GOALS, conditions=("a-b",)))


def _goal(i: int, j: int) -> Goal:
    return Goal("", -1, i, j)


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


def _save(fig: Figure, path: Path) -> np.ndarray:
    """``fig`` saved (as ``path`` without suffix), closed, and its PNG read back."""
    png = save_figure(fig, path.with_suffix(""))[0]
    plt.close(fig)
    return _image(png)


def _texts_inside(fig: Figure) -> None:
    """Every text of ``fig`` drawn with Agg lies inside the figure (1 px slack): each text
    artist's box, and each axis's tight box (the tick labels it draws: labels of ticks
    outside the view stay visible artists but are not drawn)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    axes = [a for a in fig.findobj(Axis)]
    ticks = {id(t) for a in axes for tick in a.get_major_ticks() + a.get_minor_ticks()
             for t in (tick.label1, tick.label2)}  # fmt: skip
    texts = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()
             and id(t) not in ticks]  # fmt: skip
    extents = [(t.get_text(), t.get_window_extent(renderer)) for t in texts]
    extents += [(str(a), a.get_tightbbox(renderer)) for a in axes if a.get_visible()]
    assert len(texts) > 1
    for name, extent in extents:
        if extent is None:
            continue
        assert extent.x0 >= box.x0 - 1 and extent.x1 <= box.x1 + 1, name
        assert extent.y0 >= box.y0 - 1 and extent.y1 <= box.y1 + 1, name


def _contrast_on_white(colour: str) -> float:
    """WCAG 2 contrast ratio of ``colour`` against white."""
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in to_rgb(colour)]
    luminance = 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]
    return 1.05 / (luminance + 0.05)


def test_a_label_keeps_its_look_whatever_else_the_run_holds() -> None:
    alone = method_styles(["zeta", "warping"])
    crowd = method_styles(["zeta", "alpha", "warping", "sift", "klt-sector", "min-warping", "m7"])
    assert alone["zeta"] == crowd["zeta"] == method_style("zeta")
    assert alone["warping"] == crowd["warping"]
    for label, (colour, marker, linestyle) in PINNED.items():
        assert (method_style(label).colour, method_style(label).marker) == (PALETTE[colour], marker)
        assert method_style(label).linestyle == linestyle
    # seed 001's labels look like the methods they name
    assert method_style("P") == method_style("sift") and method_style("W") == method_style(
        "warping"
    )
    assert method_style("PN").colour not in {method_style(m).colour for m in ("P", "W")}
    # other labels never take a pinned colour
    pinned = {PALETTE[c] for c, _, _ in PINNED.values()}
    looks = [method_style(f"method-{k}") for k in range(200)]
    assert {s.colour for s in looks} == set(FREE_COLOURS)
    assert not {s.colour for s in looks} & pinned
    # colour, marker and line style are picked independently: every one takes all its values,
    # and 200 labels get about as many looks as 200 uniform picks of 7 x 10 x 4 (143 expected)
    assert {s.marker for s in looks} == set(MARKERS) and {s.linestyle for s in looks} == set(
        LINESTYLES
    )
    assert len({(s.colour, s.marker, s.linestyle) for s in looks}) >= 130


def test_every_palette_colour_is_readable_on_white() -> None:
    assert all(_contrast_on_white(c) >= 3.0 for c in PALETTE), PALETTE
    assert _contrast_on_white("#DDCC77") < 3.0  # the light yellow that was dropped


def test_goal_panels_mark_failures_and_missing_estimates(tables) -> None:
    panels = {p.label: p for p in goal_panels(tables.pairs, MetricsConfig(), "a-a", _goal(1, 2))}
    assert list(panels) == LABELS
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


def test_goal_panels_read_an_abstention_as_the_run_config_says(tables) -> None:
    """(3, 4), without an estimate for "holes", neighbours goal (2, 3): its walk fails by
    default and arrives with metrics.return_ratio.no_estimate: arrived."""
    arrived = MetricsConfig(return_ratio={"no_estimate": "arrived"})
    strict = {p.label: p for p in goal_panels(tables.pairs, MetricsConfig(), "a-a", _goal(2, 3))}
    lenient = {p.label: p for p in goal_panels(tables.pairs, arrived, "a-a", _goal(2, 3))}
    assert strict["holes"].rr_failed[3, 4] and not lenient["holes"].rr_failed[3, 4]
    assert lenient["holes"].rr > strict["holes"].rr


def test_goals_know_their_world() -> None:
    frame = pd.DataFrame({"style": [None, "office", "office"], "seed": [None, 2, 2],
                          "goal_i": [1, 1, 0], "goal_j": [2, 2, 3]})  # fmt: skip
    goals = condition_goals(frame.assign(condition="a-a"), "a-a")
    assert goals == [Goal("", -1, 1, 2), Goal("office", 2, 0, 3), Goal("office", 2, 1, 2)]
    assert [g.text for g in goals] == ["(1, 2)", "(0, 3) office seed 2", "(1, 2) office seed 2"]
    assert goals[2].rows(frame).tolist() == [False, True, False]


def test_pick_goals_and_pages() -> None:
    goals = [(i, 0) for i in range(10)]
    assert pick_goals(goals, 3) == [(0, 0), (4, 0), (9, 0)]
    assert pick_goals(goals, 20) == goals
    assert pick_goals(goals, 1) == [(0, 0)]
    assert pages(goals, 4) == [goals[:4], goals[4:8], goals[8:]]
    assert pages([], 4) == []


def test_describe_times_count_each_image_once(tables) -> None:
    for condition, n_images in (("a-a", GRID.size), ("a-b", GRID.size + 2)):
        pairs = tables.pairs[tables.pairs["condition"] == condition]
        times = image_describe_times(pairs)
        assert (times.groupby("method").size() == n_images).all()
    assert condition_goals(tables.pairs, "a-b") == [_goal(1, 2), _goal(2, 3)]


def test_grid_layout_fits_journal_pages() -> None:
    tall = Grid((10, 17), 0.3, (0.0, 0.0))  # the Bielefeld grid
    for grid, n_methods in ((tall, 3), (tall, 6), (GRID, 1), (GRID, 3), (Grid((40, 2), 1.0), 2)):
        layout = grid_layout(grid, n_methods)
        assert 1 <= layout.goals_per_figure <= MAX_GOALS_PER_FIGURE
        width, height = layout.size(layout.goals_per_figure)
        assert width == (SINGLE_COLUMN if n_methods == 1 else DOUBLE_COLUMN)
        assert height <= MAX_FIGURE_HEIGHT + 1e-9
    assert grid_layout(tall, 3).goals_per_figure == 2
    assert grid_layout(tall, 6).rows_per_goal == 2


def test_every_goal_is_drawn_on_as_many_figures_as_it_takes(many_goals_run) -> None:
    per_figure = grid_layout(GRID, len(METHODS)).goals_per_figure
    expected = math.ceil(len(MANY_GOALS) / per_figure)
    assert expected > 1
    with report_style():
        styles = run_styles(many_goals_run)
        drawn = list(_goal_figures(many_goals_run, "a-b", len(MANY_GOALS) + 5, styles))
        for _, _, fig in drawn:
            plt.close(fig)
    stems = [stem for stem, _, _ in drawn]
    assert stems == [
        *(f"a-b_fields_{k}" for k in range(1, expected + 1)),
        *(f"a-b_ae_{k}" for k in range(1, expected + 1)),
    ]
    fields = [caption for stem, caption, _ in drawn if "_fields_" in stem]
    listed = " ".join(fields)
    assert all(f"({i}, {j})" in listed for i, j in MANY_GOALS)
    assert "goals shown" not in listed and f"part 1 of {expected}" in fields[0]
    with report_style():
        cut = list(_goal_figures(many_goals_run, "a-b", 2, styles))
        for _, _, fig in cut:
            plt.close(fig)
    assert [stem for stem, _, _ in cut] == ["a-b_fields_1", "a-b_ae_1"]
    assert f"(2 of {len(MANY_GOALS)} goals shown)" in cut[0][1]
    panels = [(g, goal_panels(many_goals_run.tables.pairs, MetricsConfig(), "a-b", g))
              for g in condition_goals(many_goals_run.tables.pairs, "a-b")]  # fmt: skip
    assert [len(page) for page in grid_pages(panels)] == [
        len(chunk) for chunk in pages(MANY_GOALS, per_figure)
    ]


def test_all_conditions_figures_follow_the_conditions(many_goals_run) -> None:
    with report_style():
        drawn = list(grid_figures(many_goals_run, 1))
        for *_, fig in drawn:
            plt.close(fig)
    # one condition: no heat maps; the per-goal figures last
    assert [(stem, section) for stem, section, _, _ in drawn][:3] == [
        ("ahc_1", "All conditions"),
        ("rr_1", "All conditions"),
        ("timing", "Time per call"),
    ]
    assert "(a) a-b (current: db-a, goal: db-b)" in drawn[1][2]
    assert {section for _, section, _, _ in drawn[3:]} == {
        "Appendix: per-goal figures, a-b (current: db-a, goal: db-b)"
    }


def test_metric_figure_captions_note_intervals_on_fewer_than_five_goals(
    tmp_path: Path, many_goals_run
) -> None:
    few = load_run(write_fake_run(tmp_path / "run", METHODS, conditions=("a-b",)))  # 2 goals
    for run, noted in ((few, True), (many_goals_run, False)):
        with report_style():
            drawn = list(itertools.islice(_metric_figures(run, run_styles(run)), 2))
            for *_, fig in drawn:
                plt.close(fig)
        assert [stem for stem, _, _ in drawn] == ["ahc_1", "rr_1"]
        for _, caption, _ in drawn:
            assert ("rest on 2 goals, fewer than 5" in caption) is noted, caption


def test_rr_caption_gives_the_radius_in_grid_units_and_a_non_default_reading() -> None:
    assert _rr_walks(ReturnRatioConfig()).endswith("within 0.5 grid units of the goal")
    lenient = _rr_walks(ReturnRatioConfig(success_radius=0.25, no_estimate="arrived"))
    assert "within 0.25 grid units" in lenient and "no_estimate: arrived" in lenient


def test_per_goal_panel_titles_fit_their_panel_in_two_lines(tables) -> None:
    """Label and goal on one line, what the panel shows on the next, the font shrunk (not
    below TITLE_MIN_POINTS) until each line's measured width fits the panel."""
    tall = Grid((10, 17), 0.3, (0.0, 0.0))
    for grid, n_methods in ((tall, 6), (GRID, 3), (GRID, 1)):
        width = grid_layout(grid, n_methods).panel_width
        for label, goal in (
            ("min-warping", "(0, 3) office seed 2"),
            ("sift[ratio=0.7]", "(9, 16)"),
        ):
            title = panel_title(label, goal, "12 no est., RR 0.85", width)
            lines = title.text.split("\n")
            assert lines[0].startswith(label) and len(lines) == 2, (title, width)
            assert title.points >= TITLE_MIN_POINTS
            assert all(text_width(line, title.points) <= width for line in lines), (title, width)
    with report_style():
        panels = goal_panels(tables.pairs, MetricsConfig(), "a-a", _goal(1, 2))
        fig = field_figure([(_goal(1, 2), panels)], method_styles(LABELS))
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert len(titles) == 3 and all(t.count("\n") == 1 for t in titles), titles
    plt.close(fig)


def test_ae_maps_use_the_fixed_scale(tables) -> None:
    panels = goal_panels(tables.pairs, MetricsConfig(), "a-b", _goal(2, 3))
    with report_style():
        fig = ae_figure([(_goal(2, 3), panels)])
        maps = [ax for ax in fig.axes if ax.get_title()]  # not the colour bar
        meshes = [c for ax in maps for c in ax.collections if isinstance(c, QuadMesh)]
        assert len(meshes) == 3
        assert {(m.norm.vmin, m.norm.vmax) for m in meshes} == {(0.0, AE_MAX_DEG)} == {(0, 100)}
        # 180 deg errors are clipped to the top colour; the colour bar's arrow says so
        reversed_mesh = meshes[LABELS.index("reversed")]
        top = reversed_mesh.cmap(reversed_mesh.norm(180.0))
        assert tuple(top) == tuple(reversed_mesh.cmap.get_over()) == reversed_mesh.cmap(1.0)
        colorbar = reversed_mesh.colorbar
        assert colorbar is not None and colorbar.extend == "max"
        _texts_inside(fig)
        plt.close(fig)


def test_field_arrows_stay_inside_the_axes(tables) -> None:
    styles = method_styles(LABELS)
    goals = [(_goal(i, j), goal_panels(tables.pairs, MetricsConfig(), "a-a", _goal(i, j)))
             for i, j in ((1, 2), (2, 3))]  # fmt: skip
    with report_style():
        fig = field_figure(goals, styles)
        _texts_inside(fig)
    quivers = [(ax, c) for ax in fig.axes for c in ax.collections if isinstance(c, Quiver)]
    assert len(quivers) >= 6
    for ax, quiver in quivers:
        tips = quiver.get_offsets() + np.column_stack([quiver.U, quiver.V])
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        for x, y in np.vstack([quiver.get_offsets(), tips]):
            assert x0 < x < x1 and y0 < y < y1
    # the reversed method's edge arrows point out of the grid, yet stay inside
    assert fig.get_figwidth() == DOUBLE_COLUMN
    plt.close(fig)


def test_field_arrows_take_the_method_colour_only_where_homing_succeeds(
    tables, tmp_path: Path
) -> None:
    styles = method_styles(LABELS)
    goal = _goal(1, 2)
    panels = {p.label: p for p in goal_panels(tables.pairs, MetricsConfig(), "a-a", goal)}
    with report_style():
        good = _save(field_figure([(goal, [panels["perfect"]])], styles), tmp_path / "good.png")
        bad = _save(field_figure([(goal, [panels["reversed"]])], styles), tmp_path / "bad.png")
        both = _save(field_figure([(goal, list(panels.values()))], styles), tmp_path / "all.png")
    assert _pixels_of(good, styles["perfect"].colour) > 500
    assert _pixels_of(bad, styles["reversed"].colour) == 0
    assert _pixels_of(both, styles["holes"].colour) > 500


def _ahc_rows(condition: str, method: str, ahc: list[float]) -> pd.DataFrame:
    centres = [30.0, 60.0, 90.0]
    rows = pd.DataFrame({
        "condition": condition, "method": method, "bin": [f"{c:g}" for c in centres],
        "centre_cm": centres, "n": [12, 8, 0], "ahc": ahc, "ahc_lo": [a - 0.1 for a in ahc],
        "ahc_hi": [min(1.0, a + 0.1) for a in ahc],
    })  # fmt: skip
    every = pd.DataFrame({"condition": [condition], "method": [method], "bin": ["all"],
                          "centre_cm": [np.nan], "n": [20], "ahc": [-0.9], "ahc_lo": [-0.95],
                          "ahc_hi": [0.0]})  # fmt: skip
    return pd.concat([rows, every], ignore_index=True)


def test_ahc_panels_share_one_range_and_draw_ci_bands() -> None:
    table = pd.concat([
        _ahc_rows("o-o", "P", [0.9, 0.8, np.nan]), _ahc_rows("o-o", "W", [0.7, 0.5, np.nan]),
        _ahc_rows("o-d", "P", [0.6, 0.3, np.nan]), _ahc_rows("o-d", "W", [0.2, -0.17, np.nan]),
    ], ignore_index=True)  # fmt: skip
    # lowest bin value: -0.17, its lower bound -0.27 -> -0.3 (the "all" row is not drawn)
    limits = ahc_range(table)
    assert limits == pytest.approx((-0.3, 1.0))
    assert ahc_range(table[table["condition"] == "o-o"]) == (0.0, 1.0)
    panels = [ConditionPanel(c, table[table["condition"] == c]) for c in ("o-o", "o-d")]
    with report_style():
        fig = ahc_figure(panels, method_styles(["P", "W"]), limits)
        _texts_inside(fig)
    axes = [ax for ax in fig.axes if ax.get_title(loc="left")]
    assert [ax.get_title(loc="left") for ax in axes] == ["(a) o-o", "(b) o-d"]
    assert all(ax.get_ylim() == pytest.approx(limits) for ax in axes)
    for ax in axes:
        bands = [c for c in ax.collections if isinstance(c, PolyCollection)]
        assert len(bands) == 2  # one per method
        assert [c.get_facecolor()[0][:3] for c in bands] == [
            pytest.approx(to_rgb(method_style(m).colour)) for m in ("P", "W")
        ]
    # the pairs per bin, written along the (top) x axis
    top = axes[0].child_axes[0] if axes[0].child_axes else None
    labels = [t.get_text() for t in (top or axes[0]).get_xticklabels()]
    assert labels == ["12", "8"]  # the 90 cm bin holds no pair: the axis ends before it
    assert all(ax.get_xlim() == pytest.approx((15.0, 75.0)) for ax in axes)
    plt.close(fig)


def test_ahc_distance_axis_ends_at_the_last_bin_holding_a_pair() -> None:
    """A 5 x 7 grid's pairs stop at 180 cm: bins up to 390 cm would leave half of every
    panel empty. Empty bins between bins with pairs stay (their count, 0, says so)."""
    centres = np.arange(30.0, 391.0, 30.0)
    n = np.where(centres <= 180.0, 10, 0)
    n[2] = 0  # a gap
    table = pd.DataFrame({"bin": [f"{c:g}" for c in centres], "centre_cm": centres, "n": n})
    np.testing.assert_array_equal(ahc_bins(table), np.arange(30.0, 181.0, 30.0))
    assert ahc_bins(table.assign(n=0)).tolist() == centres.tolist()  # nothing to follow
    assert ahc_bins(table.iloc[:0]).size == 0


def test_rr_bars_per_goal_and_the_mean_with_its_interval() -> None:
    goals = pd.DataFrame({
        "style": None, "seed": None, "condition": "o-o", "method": ["P", "P", "W", "W"],
        "goal_i": [1, 5, 1, 5], "goal_j": [4, 9, 4, 9], "rr": [1.0, 0.5, 0.25, np.nan],
    })  # fmt: skip
    summary = pd.DataFrame({"condition": "o-o", "method": ["P", "W"], "rr": [0.75, 0.25],
                            "rr_lo": [0.5, 0.25], "rr_hi": [1.0, 0.25]})  # fmt: skip
    panels = [RRPanel("o-o", goals, summary), RRPanel("o-d", goals, summary)]
    with report_style():
        fig = rr_figure(panels, method_styles(["P", "W"]))
        _texts_inside(fig)
    ax = fig.axes[0]
    assert ax.get_ylim() == (0.0, 1.0) and fig.axes[1].get_ylim() == (0.0, 1.0)
    heights = sorted(round(p.get_height(), 6) for p in ax.patches if p.get_width() < 1)
    # goal bars (NaN drawn as 0, marked n/a) and the two means
    assert heights == [0.0, 0.25, 0.25, 0.5, 0.75, 1.0]
    assert "n/a" in [t.get_text() for t in ax.texts]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["(1, 4)", "(5, 9)", "mean"]
    caps = [line for line in ax.get_lines() if line.get_marker() == "_"]
    assert sorted(np.round(np.concatenate([c.get_ydata() for c in caps]).astype(float), 6)) == [
        0.25,
        0.25,
        0.5,
        1.0,
    ]
    plt.close(fig)


def test_metric_figures_draw(tables, tmp_path: Path) -> None:
    styles = method_styles(LABELS)
    many_goals = tables.goals[tables.goals["condition"] == "a-a"]
    many_goals = many_goals.loc[np.repeat(many_goals.index, MAX_RR_BARS)].reset_index(drop=True)
    many_goals["goal_i"] = np.arange(len(many_goals))
    many_goals["rr"] = np.linspace(0.0, 1.0, len(many_goals))
    pairs = tables.pairs[tables.pairs["condition"] == "a-a"]
    spread = np.tile(np.linspace(0.5, 2.0, 19), len(pairs) // 19)  # times of each job vary
    pairs = pairs.assign(
        home_ms=pairs["home_ms"] * spread, describe_ms=pairs["describe_ms"] * spread
    )
    summary = tables.summary[tables.summary["condition"] == "a-a"]
    ahc = [ConditionPanel(c, tables.ahc[tables.ahc["condition"] == c]) for c in ("a-a", "a-b")]
    rr = [RRPanel(c, tables.goals[tables.goals["condition"] == c], summary) for c in ("a-a", "a-b")]
    with report_style():
        figures = {
            "ahc": ahc_figure(ahc, styles, ahc_range(tables.ahc)),
            "rr": rr_figure(rr, styles),
            "rr_boxes": rr_figure([RRPanel("a-a", many_goals, summary)], styles),
            "timing": timing_figure(image_describe_times(pairs), pairs, styles),
        }
        for name, fig in figures.items():
            _texts_inside(fig)
            image = _save(fig, tmp_path / f"{name}.png")
            assert _pixels_of(image, styles["holes"].colour) > 50, name
    assert figures["ahc"].axes[0].get_ylim() == (-1.0, 1.0)  # reversed: AHC -1 is in range
    timing_axes = figures["timing"].axes
    assert all(ax.get_yscale() == "log" for ax in timing_axes)
    ticks = [t.get_text() for t in timing_axes[1].get_xticklabels()]
    assert ticks[0] == f"holes\nmedian {5.0 * np.median(spread):.3g} ms"


def test_saving_twice_gives_the_same_bytes_in_every_format(tables, tmp_path: Path) -> None:
    panels = goal_panels(tables.pairs, MetricsConfig(), "a-a", _goal(1, 2))
    with report_style():
        fig = ae_figure([(_goal(1, 2), panels)])
        first = save_figure(fig, tmp_path / "ae")
        second = save_figure(fig, tmp_path / "again")
        plt.close(fig)
    assert [p.name for p in first] == ["ae.png", "ae.pdf", "ae.svg"]
    assert [p.name for p in second] == ["again.png", "again.pdf", "again.svg"]
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name
    assert b"CreationDate" not in first[1].read_bytes()
    assert b"<dc:date>" not in first[2].read_bytes()
    assert cv2.imread(str(first[0])).shape[1] == round(fig.get_figwidth() * 300)


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
        trajectories = _save(route_figure(results[:2], styles), tmp_path / "route.png")
        errors_fig = route_error_figure(results, styles)
        lines = {line.get_label(): line for line in errors_fig.axes[0].get_lines()}
        errors = _save(errors_fig, tmp_path / "errors.png")
    assert _pixels_of(trajectories, styles["klt-sector"].colour) > 100
    assert _pixels_of(errors, styles["sift"].colour) > 50
    assert np.allclose(lines["sift"].get_xdata(), [1.0, 3.0])
    assert np.allclose(lines["sift"].get_ydata(), [0.05, 0.05])
    assert np.allclose(lines["odometry"].get_ydata(), [0.1, 0.3])
    assert math.isclose(lines["klt-sector"].get_ydata()[0], 0.004)


def test_rr_ticks_of_one_swept_world_name_the_goal_only_and_do_not_overlap(tables) -> None:
    """A style sweep's panel holds one world (its title names it): the goal ticks are "(i, j)",
    and no two tick labels overlap, on a panel of a third of a double column."""
    styles = method_styles(LABELS)
    goals = tables.goals[tables.goals["condition"] == "a-a"].assign(style="outdoor")
    summary = tables.summary[tables.summary["condition"] == "a-a"]
    panels = [RRPanel(f"a-a {k}", goals, summary) for k in range(3)]
    with report_style():
        fig = rr_figure(panels, styles)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        labels = fig.axes[0].get_xticklabels()
        assert [t.get_text() for t in labels[:-1]] == [
            f"({i}, {j})"
            for i, j in sorted(set(zip(goals["goal_i"], goals["goal_j"], strict=True)))
        ]
        boxes = [t.get_window_extent(renderer) for t in labels]
        assert not any(a.overlaps(b) for a, b in zip(boxes, boxes[1:], strict=False))
        plt.close(fig)


def test_a_legend_of_many_long_labels_stays_inside_the_figure(tables) -> None:
    """Twelve methods with long labels under three conditions: the legend wraps into as many
    columns as fit instead of running off the figure, in any width."""
    labels = [f"{name}-{k}" for k in range(4) for name in ("fourier-warping", "block-matching",
                                                             "visual-compass")]  # fmt: skip
    goals = tables.goals[tables.goals["condition"] == "a-a"]
    summary = tables.summary[tables.summary["condition"] == "a-a"]
    source = goals[goals["method"] == LABELS[0]]
    many = pd.concat([source.assign(method=label) for label in labels], ignore_index=True)
    many_summary = pd.concat(
        [summary[summary["method"] == LABELS[0]].assign(method=label) for label in labels]
    )
    with report_style():
        fig = rr_figure([RRPanel(f"a-a {k}", many, many_summary) for k in range(3)],
                        method_styles(labels))  # fmt: skip
        _texts_inside(fig)
        legend_texts = [t.get_text() for t in fig.legends[0].get_texts()]
        assert set(labels) <= set(legend_texts)
        plt.close(fig)


def test_trajectory_panel_titles_do_not_overlap() -> None:
    """Four trials side by side in a double column: each panel's title stays within its own
    horizontal extent plus the gap to the next panel."""
    results = [
        _route("klt-sector", length, 0.004, 0.1 * length) for length in (2.0, 4.0, 6.0, 10.0)
    ]
    with report_style():
        fig = route_figure(results, method_styles({r.label for r in results}))
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        titles = [ax.title.get_window_extent(renderer) for ax in fig.axes if ax.get_title()]
        assert len(titles) == len(results)
        assert not any(a.overlaps(b) for a, b in zip(titles, titles[1:], strict=False))
        plt.close(fig)
