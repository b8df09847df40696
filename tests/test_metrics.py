"""AE, AHC and home-vector fields on hand-made fields whose answers are known."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.analysis.metrics import (
    HomeField,
    ae_summary,
    ahc,
    ahc_by_distance,
    angular_errors,
    distance_bins,
)
from homebench.geometry import Grid

GRID = Grid((10, 17), 0.3, origin=(1.0, -2.0))
GOAL = (3, 11)


def field_errors(angles: np.ndarray) -> np.ndarray:
    """AE (radians) of a world-frame field towards GOAL at every grid position but the goal."""
    xy = GRID.position(*np.indices(GRID.shape))
    keep = np.ones(GRID.shape, dtype=bool)
    keep[GOAL] = False
    return angular_errors(angles[keep], xy[keep], GRID.position(*GOAL))


# --------------------------------------------------------------------------- AE


@pytest.mark.parametrize(
    ("goal_offset", "estimate", "expected"),
    [
        ((1.0, 0.0), 0.0, 0.0),  # goal along +x, estimate +x
        ((1.0, 0.0), np.pi / 2, np.pi / 2),  # goal along +x, estimate +y
        ((1.0, 0.0), np.pi, np.pi),  # goal along +x, estimate -x (a C - H sign bug)
        ((0.0, 2.0), np.pi / 2, 0.0),  # goal along +y, estimate +y
        ((0.0, 2.0), 0.0, np.pi / 2),  # goal along +y, estimate +x (an x/y swap)
        ((0.0, -2.0), -np.pi / 2, 0.0),  # goal along -y
        ((-1.0, -1.0), -3 * np.pi / 4, 0.0),  # goal down-left
        ((-1.0, 0.0), np.pi - 0.1, 0.1),  # wrap across +-pi
        ((-1.0, 0.0), -np.pi + 0.1, 0.1),
    ],
)
def test_angular_errors_along_axes(goal_offset, estimate, expected):
    current = np.array([0.5, -0.25])
    ae = angular_errors(estimate, current, current + np.asarray(goal_offset))
    assert ae == pytest.approx(expected, abs=1e-12)


def test_angular_errors_vectorised_and_missing():
    current = np.zeros((3, 2))
    goal = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    ae = angular_errors([0.1, np.nan, np.pi / 4], current, goal)
    np.testing.assert_allclose(ae, [0.1, np.nan, 0.0], atol=1e-12)


def test_angular_errors_rejects_pair_at_goal():
    with pytest.raises(ValueError, match="1 pair"):
        angular_errors([0.0, 0.0], [[0.0, 0.0], [1.0, 1.0]], [[1.0, 0.0], [1.0, 1.0]])


def test_ae_summary_counts_missing():
    ae = np.radians([10.0, 20.0, 60.0, np.nan])
    s = ae_summary(ae)
    assert (s["n"], s["n_missing"]) == (4, 1)
    assert s["missing_share"] == pytest.approx(0.25)
    assert s["mean_deg"] == pytest.approx(30.0)
    assert s["median_deg"] == pytest.approx(20.0)
    assert s["mean_rad"] == pytest.approx(np.radians(30.0))


def test_ae_summary_all_missing_is_explicit():
    s = ae_summary([np.nan, np.nan])
    assert (s["n"], s["n_missing"], s["missing_share"]) == (2, 2, 1.0)
    assert np.isnan(s["mean_rad"]) and np.isnan(s["median_deg"])


# --------------------------------------------------------------------------- AHC


def test_perfect_field_ae_zero_ahc_one():
    ae = field_errors(HomeField.ideal(GRID, GOAL).angles)
    assert np.max(ae) == pytest.approx(0.0, abs=1e-12)
    assert ahc(ae) == pytest.approx(1.0)


def test_rotated_field_ahc_zero():
    ae = field_errors(HomeField.ideal(GRID, GOAL).angles + np.pi / 2)
    np.testing.assert_allclose(ae, np.pi / 2, atol=1e-12)
    assert ahc(ae) == pytest.approx(0.0, abs=1e-12)


def test_field_pointing_away_ahc_minus_one():
    assert ahc(field_errors(HomeField.ideal(GRID, GOAL).angles + np.pi)) == pytest.approx(-1.0)


def test_ahc_missing_modes():
    ae = [0.0, np.nan]
    assert ahc(ae) == pytest.approx(1.0)
    assert ahc(ae, missing="orthogonal") == pytest.approx(np.cos(np.pi / 4))
    assert np.isnan(ahc([np.nan]))
    assert ahc([np.nan], missing="orthogonal") == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="missing"):
        ahc(ae, missing="drop")


def test_bins_put_multiples_of_30cm_in_their_bin():
    k = np.arange(1, 14)
    table = ahc_by_distance(np.radians(k.astype(float)), 0.3 * k)
    bins = table.iloc[:-1]
    assert list(bins["centre_cm"]) == list(range(30, 391, 30))
    assert (bins["n"] == 1).all()
    np.testing.assert_allclose(bins["mean_ae_deg"], k)
    np.testing.assert_allclose(bins["ahc"], np.cos(np.radians(k)))
    assert (table.iloc[0]["low_cm"], table.iloc[0]["high_cm"]) == (15.0, 45.0)
    assert bins.iloc[-1]["high_cm"] == 405.0


def test_bins_nearest_centre_and_pairs_outside():
    d = np.array([0.0, 0.449, 0.451, 0.3 * 2**0.5, 4.049, 4.06])
    ae = np.array([0.1, 0.2, 0.3, np.nan, 0.5, 0.6])
    table = ahc_by_distance(ae, d).set_index("bin")
    assert table.loc["30", "n"] == 2  # 44.9 cm and 42.4 cm (a diagonal neighbour)
    assert table.loc["30", "n_missing"] == 1
    assert table.loc["30", "mean_ae_rad"] == pytest.approx(0.2)
    assert table.loc["60", "n"] == 1
    assert table.loc["390", "n"] == 1
    assert table["n"].iloc[:-1].sum() == 4  # 0 cm and 406 cm lie outside every bin
    assert (table.loc["all", "n"], table.loc["all", "n_missing"]) == (6, 1)
    assert table.loc["all", "mean_ae_rad"] == pytest.approx(np.mean([0.1, 0.2, 0.3, 0.5, 0.6]))
    assert np.isnan(table.loc["120", "ahc"]) and table.loc["120", "n"] == 0


def test_bins_on_a_whole_grid_match_rounded_grid_distance():
    ij = np.indices(GRID.shape).reshape(2, -1).T
    grid_units = np.hypot(*(ij - GOAL).T)
    away = grid_units > 0
    d_m = np.linalg.norm(GRID.position(*ij.T) - GRID.position(*GOAL), axis=-1)
    table = ahc_by_distance(np.zeros(away.sum()), d_m[away]).iloc[:-1]
    expected = [np.sum(np.rint(grid_units[away]) == k) for k in range(1, 14)]
    assert list(table["n"]) == expected


def test_distance_bins_masks_match_the_table():
    d = np.array([0.0, 0.3, 0.31, 0.6, 4.1])
    bins, masks = distance_bins(d)
    assert masks.shape == (14, 5) and list(bins["bin"])[-1] == "all"
    assert masks[-1].all()  # "all" holds every pair, those outside every bin included
    np.testing.assert_array_equal(np.flatnonzero(masks[0]), [1, 2])
    table = ahc_by_distance(np.zeros(5), d)
    np.testing.assert_array_equal(table["n"], masks.sum(axis=1))


def test_bins_missing_orthogonal_mode():
    table = ahc_by_distance([0.0, np.nan], [0.3, 0.3], missing="orthogonal")
    assert table.iloc[0]["ahc"] == pytest.approx(np.cos(np.pi / 4))
    assert table.iloc[0]["n_missing"] == 1


def test_bins_reject_bad_input():
    with pytest.raises(ValueError, match="pairs"):
        ahc_by_distance([0.0, 0.1], [0.3])
    with pytest.raises(ValueError, match="increasing"):
        ahc_by_distance([0.0], [0.3], bins_cm=[60, 30])


# --------------------------------------------------------------------------- HomeField


def test_ideal_field_points_at_goal_along_axes():
    f = HomeField.ideal(GRID, GOAL)
    assert f.angles[0, GOAL[1]] == pytest.approx(0.0)  # left of the goal: +x
    assert f.angles[GOAL[0], 0] == pytest.approx(np.pi / 2)  # below the goal: +y
    assert f.angles[GOAL[0], 16] == pytest.approx(-np.pi / 2)
    assert abs(f.angles[9, GOAL[1]]) == pytest.approx(np.pi)
    np.testing.assert_allclose(f.goal_xy, [1.9, 1.3])


def test_from_robot_frame_uses_headings():
    rng = np.random.default_rng(3)
    truth = HomeField.ideal(GRID, GOAL).angles
    headings = rng.uniform(-np.pi, np.pi, GRID.shape)
    azimuths = truth - headings
    azimuths[0, 0] = np.nan
    f = HomeField.from_robot_frame(GRID, GOAL, azimuths, headings)
    err = np.abs(np.angle(np.exp(1j * (f.angles - truth))))
    assert np.isnan(f.angles[0, 0])
    assert np.nanmax(err) < 1e-12
    scalar = HomeField.from_robot_frame(GRID, GOAL, np.zeros(GRID.shape), np.pi / 2)
    np.testing.assert_allclose(scalar.angles, np.pi / 2)


def test_home_field_validates_and_freezes():
    with pytest.raises(ValueError, match="shape"):
        HomeField(GRID, GOAL, np.zeros((17, 10)))
    with pytest.raises(ValueError, match="outside"):
        HomeField(GRID, (10, 0), np.zeros(GRID.shape))
    source = np.zeros(GRID.shape)
    f = HomeField(GRID, GOAL, source)
    source[0, 0] = 1.0
    assert f.angles[0, 0] == 0.0
    with pytest.raises(ValueError):
        f.angles[0, 0] = 1.0


def test_the_two_ahc_definitions_against_hand_computed_values() -> None:
    """Seed 001's eq. 12 (cos of the mean AE) and the mean of the cosines (Vardy & Möller)."""
    ae = np.radians([0.0, 60.0, 120.0])
    assert ahc(ae) == pytest.approx(0.5)  # cos 60
    assert ahc(ae, definition="mean_cos") == pytest.approx((1.0 + 0.5 - 0.5) / 3)
    holes = np.radians([0.0, 90.0, np.nan])
    assert ahc(holes) == pytest.approx(np.cos(np.radians(45.0)))
    assert ahc(holes, definition="mean_cos") == pytest.approx(0.5)
    assert ahc(holes, "orthogonal") == pytest.approx(0.5)  # cos(mean(0, 90, 90))
    assert ahc(holes, "orthogonal", "mean_cos") == pytest.approx(1.0 / 3.0)


def test_a_run_reports_the_ahc_of_its_configured_definition(tmp_path) -> None:
    from test_report_runs import FakeMethod, write_fake_run

    from homebench.config import MetricsConfig
    from homebench.evaluation.results import build_tables

    holes = FakeMethod("holes", 30.0, frozenset({(0, 0), (3, 4)}))  # 4 of 38 pairs missing
    run = write_fake_run(tmp_path, [holes, FakeMethod("ten", 10.0)])
    paper = build_tables(run, MetricsConfig()).summary.set_index("method")
    vardy = MetricsConfig.model_validate({"ahc": {"definition": "mean_cos"}})
    other = build_tables(run, vardy).summary.set_index("method")
    share = 4 / 38
    mean90 = (1 - share) * 30.0 + share * 90.0
    assert paper.loc["holes", "ahc_missing90"] == pytest.approx(np.cos(np.radians(mean90)))
    assert other.loc["holes", "ahc_missing90"] == pytest.approx(
        (1 - share) * np.cos(np.radians(30.0))
    )
    # every pair with an estimate errs alike: the definitions agree there
    assert other.loc["holes", "ahc"] == pytest.approx(paper.loc["holes", "ahc"])
    tables = build_tables(run, vardy)
    row = tables.comparisons.set_index(["metric"]).loc["ahc"]
    assert row["value_b"] == pytest.approx(np.cos(np.radians(10.0)))
