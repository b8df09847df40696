"""The papers' findings as tested claims, on synthetic tables whose truth is known."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from homebench.analysis.findings import (
    FAR_RANGE_M,
    findings_table,
    route_findings,
    sift_findings,
)

CONDITIONS = ("original-original", "original-arboreal", "original-day")
N_GOALS, N_CURRENTS = 12, 30


def _tables(mean_ae_deg, rr, seed: int = 0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Pairs and RR starts of P, PN and W under the three conditions, 12 goals each.

    ``mean_ae_deg(method, condition, far)`` and ``rr(method, condition)`` give each cell's
    truth; every goal adds its own offset (goal-level noise, shared by the methods)."""
    rng = np.random.default_rng(seed)
    pairs, starts = [], []
    goal_offset = rng.normal(0, 2.0, N_GOALS)
    distance = np.linspace(0.3, 3.9, N_CURRENTS)
    for condition in CONDITIONS:
        for method in ("P", "PN", "W"):
            for g in range(N_GOALS):
                far = distance >= FAR_RANGE_M
                truth = np.array([mean_ae_deg(method, condition, f) for f in far])
                ae = np.abs(truth + goal_offset[g] + rng.normal(0, 3.0, N_CURRENTS))
                pairs.append(
                    pd.DataFrame(
                        {
                            "seed": 0,
                            "condition": condition,
                            "method": method,
                            "goal_i": g,
                            "goal_j": 0,
                            "current_i": np.arange(N_CURRENTS),
                            "current_j": 1,
                            "ae": np.radians(np.minimum(ae, 180)),
                            "distance_m": distance,
                        }
                    )
                )
                success = rng.random(N_CURRENTS) < rr(method, condition)
                starts.append(
                    pd.DataFrame(
                        {
                            "seed": 0,
                            "condition": condition,
                            "method": method,
                            "goal_i": g,
                            "goal_j": 0,
                            "start_i": np.arange(N_CURRENTS),
                            "start_j": 1,
                            "success": success,
                        }
                    )
                )
    return pd.concat(pairs, ignore_index=True), pd.concat(starts, ignore_index=True)


def _paper_world(method: str, condition: str, far: bool) -> float:
    """The paper's picture: P best (but worse than W far away), elimination helps, W
    collapses under day."""
    if far:
        return {"P": 45.0, "PN": 55.0, "W": 15.0 if condition != "original-day" else 70.0}[method]
    base = {"P": 5.0, "PN": 12.0, "W": 15.0}[method]
    return base + (55.0 if method == "W" and condition == "original-day" else 0.0)


def _paper_rr(method: str, condition: str) -> float:
    return {"P": 0.97, "PN": 0.85, "W": 0.7 if condition != "original-day" else 0.2}[method]


def test_the_paper_world_confirms_every_claim():
    pairs, starts = _tables(_paper_world, _paper_rr)
    table = findings_table(sift_findings(pairs, starts)).set_index("finding")
    assert set(table["verdict"]) == {"holds"}, table[["effect", "lo", "hi", "p_holm", "verdict"]]
    assert (table["place"] == "all").all() and (table["clusters"] == N_GOALS).all()
    assert (table["lo"] > 0).all()
    # 12 goals: the exact sign-flip test's smallest p is 2 / 2**12
    assert table["p"].min() == pytest.approx(2 / 2**12)


def test_equal_methods_are_not_significant_and_reversals_are_opposite():
    """PN equal to P: elimination claims not significant. W better than P everywhere: the
    P-beats-W claims come out opposite."""

    def world(method: str, condition: str, far: bool) -> float:
        return {"P": 20.0, "PN": 20.0, "W": 8.0}[method]

    pairs, starts = _tables(world, lambda m, c: {"P": 0.8, "PN": 0.8, "W": 0.95}[m])
    table = findings_table(sift_findings(pairs, starts)).set_index("finding")
    for condition in CONDITIONS:
        assert table.loc[f"P<PN AE {condition}", "verdict"] == "not significant"
        assert table.loc[f"P<W AE {condition}", "verdict"] == "opposite"
        assert table.loc[f"P>W RR {condition}", "verdict"] == "opposite"
    assert table.loc["day hits W harder", "verdict"] == "not significant"


def test_findings_are_reported_per_style_and_are_deterministic():
    a = _tables(_paper_world, _paper_rr, seed=1)
    b = _tables(lambda m, c, f: {"P": 20.0, "PN": 20.0, "W": 8.0}[m], _paper_rr, seed=2)
    pairs = pd.concat([a[0].assign(style="lab"), b[0].assign(style="posters")])
    starts = pd.concat([a[1].assign(style="lab"), b[1].assign(style="posters")])
    table = findings_table(sift_findings(pairs, starts))
    assert sorted(table["place"].unique()) == ["lab", "posters"]
    by_place = table.set_index(["place", "finding"])["verdict"]
    assert by_place[("lab", "P<W AE original-day")] == "holds"
    assert by_place[("posters", "P<W AE original-day")] == "opposite"
    shuffled = [frame.sample(frac=1.0, random_state=3) for frame in (pairs, starts)]
    again = findings_table(sift_findings(*shuffled))
    pd.testing.assert_frame_equal(table, again)


def _routes(visual_slope: float, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    rows = []
    for k, length in enumerate(np.repeat([2.0, 4.0, 6.0, 8.0, 10.0], 4)):
        rows.append(
            {
                "seed": 0,
                "trial": f"tour-{length:g}m-r{k % 4}",
                "length_m": length,
                "visual_error_m": 0.006 + visual_slope * length + rng.normal(0, 0.001),
                "odometry_error_m": 0.1 * length + abs(rng.normal(0, 0.05)),
            }
        )
    return pd.DataFrame(rows)


def test_route_findings():
    table = findings_table(route_findings(_routes(0.0))).set_index("finding")
    assert table.loc["visual<odometry", "verdict"] == "holds"
    assert table.loc["odometry grows", "verdict"] == "holds"
    assert table.loc["visual flat", "verdict"] == "holds"  # the slope's interval under 1 mm/m
    assert table.loc["odometry grows", "effect"] == pytest.approx(10.0, rel=0.1)  # cm per m
    growing = findings_table(route_findings(_routes(0.005))).set_index("finding")
    assert growing.loc["visual flat", "verdict"] == "opposite"  # 5 mm per m


def _paper_run(folder, world: str = ""):
    """A run folder of seed 001's experiment that sweeps no style (as a manifest database's,
    or ``configs/sift_paper.yaml``): P best, W worst."""
    from test_report_runs import FakeMethod, write_fake_run

    methods = [FakeMethod("P", 5.0), FakeMethod("PN", 12.0), FakeMethod("W", 25.0)]
    goals = ((0, 0), (1, 2), (2, 3), (3, 4), (0, 4), (3, 0))
    return write_fake_run(folder, methods, goals, conditions=CONDITIONS, world=world)


def test_findings_of_runs_that_sweep_no_style_one_or_several(tmp_path) -> None:
    """The command crashed on every run without ``styles:`` (the run folder's name was taken
    for a style)."""
    from click.testing import CliRunner

    from homebench.cli import main

    one = _paper_run(tmp_path / "bielefeld")
    result = CliRunner().invoke(main, ["findings", str(one)])
    assert result.exit_code == 0, result.output
    assert "| bielefeld | P errs less than W under original-original" in result.stdout
    other = _paper_run(tmp_path / "own-room", world="own")
    result = CliRunner().invoke(main, ["findings", str(one), str(other)])
    assert result.exit_code == 0, result.output
    tested = result.stdout.split("Not tested")[0]  # the far-range finding: grid too small
    rows = [line for line in tested.splitlines()[4:] if line.startswith("|")]
    places = {row.split("|")[1].strip() for row in rows}
    assert places == {"bielefeld", "own-room"}
    again = _paper_run(tmp_path / "copy")  # the same images as bielefeld: goals pooled twice
    result = CliRunner().invoke(main, ["findings", str(one), str(other), str(again)])
    assert result.exit_code == 0  # each run that sweeps no style is a place of its own


def test_runs_pooled_in_one_style_that_repeat_a_world_are_refused(tmp_path) -> None:
    import json

    from click.testing import CliRunner

    from homebench.cli import main

    runs = [_paper_run(tmp_path / name) for name in ("a", "b")]
    for run in runs:  # both swept the posters style, in the same world
        for job in (run / "jobs").iterdir():
            record = json.loads(job.read_text())
            job.write_text(json.dumps(record | {"style": "posters", "seed": 0}))
    result = CliRunner().invoke(main, ["findings", *map(str, runs)])
    assert result.exit_code == 2, result.output
    assert "runs a and b both hold" in result.stderr and "give each world once" in result.stderr


def test_each_ae_finding_is_tested_with_abstentions_as_90_deg_and_left_out() -> None:
    """P abstains on 40 % of its pairs under day: left out (the paper's AHC) it 'drops only
    slightly' while W's AE rises by 20 deg; counted as 90 deg its AE rises by 34 deg."""

    def world(method: str, condition: str, far: bool) -> float:
        base = {"P": 5.0, "PN": 12.0, "W": 10.0}[method]
        return base + (20.0 if method == "W" and condition == "original-day" else 0.0)

    pairs, starts = _tables(world, _paper_rr)
    rng = np.random.default_rng(5)
    abstains = (pairs["method"] == "P") & (pairs["condition"] == "original-day")
    pairs.loc[abstains & (rng.random(len(pairs)) < 0.4), "ae"] = np.nan
    table = findings_table(sift_findings(pairs, starts)).set_index("finding")
    assert table.loc["day hits W harder (missing left out)", "verdict"] == "holds"
    assert table.loc["day hits W harder (missing left out)", "missing"] == "left out"
    assert table.loc["day hits W harder", "verdict"] == "opposite"
    assert table.loc["day hits W harder", "missing"] == "as 90 deg"
    assert table.loc["P>W RR original-day", "missing"] == ""  # RR: no missing estimates


def test_the_findings_view_says_how_each_ae_finding_counts_a_missing_estimate() -> None:
    from homebench.report.across_runs.findings import MISSING_NOTE, findings_view

    pairs, starts = _tables(_paper_world, _paper_rr)
    view = findings_view(findings_table(sift_findings(pairs, starts)))
    shown = view.text_frame()
    assert list(shown.columns[:3]) == ["place", "finding", "pairs without estimate"]
    # an AE finding's two rows read alike but for how they count a missing estimate
    ways = shown.groupby("finding")["pairs without estimate"].agg(tuple)
    assert set(ways) == {("as 90 deg", "left out"), ("--",)}  # --: a return-ratio finding
    assert MISSING_NOTE in view.notes
    routes = findings_view(findings_table(route_findings(_routes(0.0))))
    assert "pairs without estimate" not in routes.frame.columns and routes.notes == ()


def test_missing_jobs_are_reported(tmp_path) -> None:
    from click.testing import CliRunner

    from homebench.cli import main

    run = _paper_run(tmp_path / "bielefeld")
    victim = sorted((run / "jobs").glob("*.json"))[0]
    victim.unlink()
    result = CliRunner().invoke(main, ["findings", str(run)])
    assert result.exit_code == 0, result.output
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"homebench: warning: bielefeld: missing jobs/{victim.name} ("), line
