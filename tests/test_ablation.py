"""The ablation's analysis on made-up level tables whose answers are known."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from homebench.analysis.ablation import (
    contrast_changes,
    default_places,
    findings_by_level,
    level_changes,
    level_summary,
    sift_contrasts,
    stack_levels,
    with_places,
)
from homebench.analysis.findings import SiftRoles

STYLES = ("posters", "lab", "outdoor")
GOALS = ((0, 0), (1, 2), (2, 1), (0, 2), (2, 0))
CURRENTS = [(i, j) for i in range(3) for j in range(3)]
ROLES = SiftRoles(p="P", pn="PN", w="W")
N_BOOT = 400


def _pairs(ae_deg: dict[tuple[str, str], float], missing: frozenset = frozenset()) -> pd.DataFrame:
    """A level's pair table: every (condition, method) of ``ae_deg`` with that AE (degrees) at
    every pair of every style, 5 goals on a 3 x 3 grid; ``missing``: current positions
    without an estimate."""
    rows = [
        {
            "style": style,
            "seed": 0,
            "condition": condition,
            "method": method,
            "goal_i": g[0],
            "goal_j": g[1],
            "current_i": c[0],
            "current_j": c[1],
            "ae": math.nan if c in missing else math.radians(value),
            "distance_m": 0.3 * math.dist(g, c),
            "error": None,
            "gives_direction": True,
        }
        for (condition, method), value in ae_deg.items()
        for style in STYLES
        for g in GOALS
        for c in CURRENTS
        if c != g
    ]
    return pd.DataFrame(rows).astype({"style": "string", "seed": "Int64"})


def _starts(success: dict[tuple[str, str], bool]) -> pd.DataFrame:
    """Return-ratio starts: every start of every goal succeeds or fails as ``success`` says."""
    pairs = _pairs({key: 0.0 for key in success})
    starts = pairs.rename(columns={"current_i": "start_i", "current_j": "start_j"})
    return starts.assign(
        success=[success[k] for k in zip(starts.condition, starts.method, strict=True)]
    )


PLACES = default_places(STYLES)
OO = "original-original"


def test_places_pool_the_rooms_and_keep_every_style():
    assert PLACES == {
        "posters": ("posters",),
        "lab": ("lab",),
        "outdoor": ("outdoor",),
        "indoor": ("posters", "lab"),
    }
    placed = with_places(_pairs({(OO, "m"): 1.0}), PLACES)
    assert placed["place"].value_counts().to_dict() == {
        "indoor": 80,
        "posters": 40,
        "lab": 40,
        "outdoor": 40,
    }


def test_summary_gives_each_levels_ahc_with_the_goals_of_its_place():
    pairs = stack_levels({"default": _pairs({(OO, "m"): 10.0}), "x": _pairs({(OO, "m"): 30.0})})
    summary = level_summary(pairs, PLACES).set_index(["place", "level"])
    assert summary.loc[("lab", "x"), "ahc"] == pytest.approx(math.cos(math.radians(30)))
    assert summary.loc[("lab", "x"), "ahc_lo"] == pytest.approx(math.cos(math.radians(30)))
    assert summary.loc[("indoor", "default"), "n_goals"] == 10
    assert summary.loc[("outdoor", "default"), "mean_ae_deg"] == pytest.approx(10.0)


def test_a_change_is_paired_with_the_sign_flip_floor_of_its_goals():
    pairs = stack_levels({"default": _pairs({(OO, "m"): 10.0}), "x": _pairs({(OO, "m"): 30.0})})
    changes = level_changes(pairs, PLACES, "default", n_boot=N_BOOT)
    row = changes.set_index(["place", "missing"]).loc[("indoor", "as 90 deg")]
    expected = math.cos(math.radians(30)) - math.cos(math.radians(10))
    assert row["change"] == pytest.approx(expected) and row["lo"] == pytest.approx(expected)
    assert row["mean_ae_change_deg"] == pytest.approx(20.0)
    assert row["p"] == pytest.approx(2 / 2**10) and row["n_goals"] == 10
    per_style = changes[changes["place"] == "lab"]
    assert np.allclose(per_style["p"], 2 / 2**5)
    assert np.allclose(per_style["p_holm"], 2 * 2 / 2**5)  # Holm over the two ways


def test_a_level_that_abstains_costs_ahc90_only():
    base = _pairs({(OO, "m"): 0.0})
    holes = frozenset(CURRENTS[:4])
    pairs = stack_levels({"default": base, "x": _pairs({(OO, "m"): 0.0}, holes)})
    changes = level_changes(pairs, PLACES, "default", n_boot=N_BOOT)
    rows = changes[changes["place"] == "outdoor"].set_index("missing")
    assert rows.loc["left out", "change"] == pytest.approx(0.0)
    n_holes = sum(len([c for c in holes if c != g]) for g in GOALS)
    assert rows.loc["left out", "n_excluded"] == n_holes
    share = n_holes / (len(GOALS) * 8)
    assert rows.loc["as 90 deg", "change"] == pytest.approx(math.cos(share * math.pi / 2) - 1)


def test_failed_pairs_are_left_out_of_every_level():
    default, level = _pairs({(OO, "m"): 10.0}), _pairs({(OO, "m"): 30.0})
    level.loc[0, "error"] = "boom"
    changes = level_changes(
        stack_levels({"default": default, "x": level}), PLACES, "default", n_boot=N_BOOT
    )
    assert changes.set_index(["place", "missing"]).loc[("posters", "left out"), "n_pairs"] == 39


def test_a_findings_effect_and_its_change_come_from_the_same_pairs():
    default = _pairs({(OO, "P"): 10.0, (OO, "W"): 30.0, (OO, "PN"): 20.0})
    level = _pairs({(OO, "P"): 10.0, (OO, "W"): 10.0, (OO, "PN"): 20.0})
    pairs = stack_levels({"default": default, "x": level})
    found = contrast_changes(pairs, sift_contrasts(ROLES), PLACES, "default", n_boot=N_BOOT)
    assert set(found["finding"]) == {"P<W AE original-original", "P<PN AE original-original"}
    rows = found[(found["place"] == "indoor") & (found["missing"] == "as 90 deg")]
    p_w = rows.set_index(["finding", "level"]).loc["P<W AE original-original"]
    assert p_w.loc["default", "effect"] == pytest.approx(20.0)
    assert p_w.loc["x", "effect"] == pytest.approx(0.0)
    assert p_w.loc["x", "change"] == pytest.approx(-20.0) and p_w.loc["x", "hi"] == pytest.approx(
        -20.0
    )
    assert p_w.loc["x", "p"] == pytest.approx(2 / 2**10)
    assert np.isnan(p_w.loc["default", "p_holm"])


def test_findings_hold_in_the_pool_where_one_style_cannot_tell():
    ae = {(OO, "P"): 10.0, (OO, "W"): 30.0, (OO, "PN"): 20.0}
    success = {(OO, "P"): True, (OO, "W"): False, (OO, "PN"): True}
    pairs = stack_levels({"default": _pairs(ae), "x": _pairs(ae)})
    starts = stack_levels({"default": _starts(success), "x": _starts(success)})
    found = findings_by_level(pairs, starts, PLACES, ROLES, n_boot=N_BOOT)
    assert set(found["level"]) == {"default", "x"}
    assert not found["finding"].str.contains("arboreal|original-day").any()  # not in the tables
    verdict = found.set_index(["level", "place", "finding"])["verdict"]
    assert verdict[("x", "indoor", "P<W AE original-original")] == "holds"
    assert verdict[("x", "lab", "P<W AE original-original")] == "not significant"  # 5 goals
