"""Claims in route and closed-loop configs: checked before any trial, recorded with when they
were stated, tested by `homebench findings` (paired over trials, Holm with the findings)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from click.testing import CliRunner
from conftest import arena_config, run_config
from test_closed_loop_run import TINY
from test_findings_claims import _tables
from test_report_routes import ERRORS, write_route_run

from homebench.analysis.user_claims import trial_difference
from homebench.claim_spec import ClaimEntry
from homebench.cli import main

ROUTE = {
    "kind": "route",
    "name": "r",
    "routes": [{"name": "line", "waypoints": [[1.7, 1.8], [1.7, 4.8]]}],
}


def _run(tmp_path: Path, config: dict, name: str = "run", *options: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**config, "output": str(tmp_path / name)}))
    return CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report", *options])


def test_a_closed_loop_claim_is_recorded_before_the_trials_and_tested(tmp_path: Path) -> None:
    claims = [
        {"better": "warping", "than": "random", "metric": "success"},
        {"better": "truth", "than": "warping", "metric": "final_error", "condition": "posters"},
    ]
    result = _run(tmp_path, {**TINY, "controls": ["truth", "random"], "claims": claims})
    assert result.exit_code == 0, result.output
    recorded = json.loads((tmp_path / "run" / "config.resolved.json").read_text())["claims"]
    assert [c["results_before"] for c in recorded] == [0, 0] and recorded[0]["stated"]
    found = CliRunner().invoke(main, ["findings", str(tmp_path / "run")])
    assert found.exit_code == 0, found.output
    tested, untested = _tables(found.stdout)
    rows = {row[1]: row for row in tested}
    success = rows["warping beats random in success over all trials"]
    # place, finding, effect, interval, unit, trials (12 starts around one goal: each start
    # its own cluster), p (Holm over the run's 2 claims), verdict, stated
    assert success[0] == "run" and success[4] == "success share" and success[5] == "12"
    assert success[-1].endswith("before any result")
    trials = pd.read_csv(tmp_path / "run" / "tables" / "trials.csv").set_index("method")
    rate = trials.loc["warping", "success"].mean() - trials.loc["random", "success"].mean()
    assert float(success[2]) == round(rate, 2)
    assert success[-2] == ("holds" if float(success[-3]) < 0.05 else "not significant")
    assert rows["truth beats warping in final_error under posters"][5] == "12"
    assert untested == [["run", "papers' findings", "no paper finding for closed-loop runs"]]
    assert "--role" not in found.stdout  # closed-loop runs take no roles
    pooled = CliRunner().invoke(main, ["findings", str(tmp_path / "run"), "--pool", "all"])
    assert pooled.exit_code == 2 and "no paper finding for closed-loop runs" in pooled.stderr


def test_a_route_claim_is_tested_beside_seed_000s_findings(tmp_path: Path) -> None:
    write_route_run(tmp_path / "run")
    path = tmp_path / "run" / "config.resolved.json"
    claims = [
        {"better": "klt-sector", "than": "odometry", "metric": "final_error",
         "stated": "2026-01-02T03:04:05+00:00", "results_before": 0},
        {"better": "klt-sector", "than": "odometry", "metric": "success", "condition": "line",
         "margin": 0.1},
    ]  # fmt: skip
    path.write_text(json.dumps(json.loads(path.read_text()) | {"claims": claims}))
    found = CliRunner().invoke(main, ["findings", str(tmp_path / "run")])
    assert found.exit_code == 0, found.output
    tested, _ = _tables(found.stdout)
    assert len(tested) == 5  # seed 000's three findings and the two claims, Holm over all
    rows = {row[1]: row for row in tested}
    error = rows["klt-sector beats odometry in final_error over all trials"]
    effect = np.mean([odometry - visual for visual, odometry in ERRORS.values()])
    assert abs(float(error[2]) - effect) < 0.0051 and error[4] == "m of final error"
    assert error[5] == "6" and error[-1] == "2026-01-02 03:04 UTC, before any result"
    # six trials, all differences positive: sign-flip p = 2 / 2**6 for both, Holm over the
    # four p-values (two findings, two claims; the flat finding is an equivalence claim)
    visual = rows["visual homing ends nearer home than odometry-based homing"]
    assert float(visual[-3]) == float(error[-3]) == 4 * 2 / 2**6
    success = rows["klt-sector beats odometry in success under line (by more than 0.1)"]
    assert success[5] == "6" and success[-1] == "not recorded by a run"


def test_a_missing_label_is_a_config_error_before_any_trial(tmp_path: Path) -> None:
    claims = [{"better": "warping", "than": "randon", "metric": "success"}]
    result = _run(tmp_path, {**TINY, "claims": claims})
    assert result.exit_code == 2
    assert "claims.0.than: no method labelled 'randon' (did you mean 'random'?)" in result.stderr
    assert not (tmp_path / "run").exists()
    claims = [{"better": "klt-sector", "than": "odometry", "metric": "success", "condition": "x"}]
    result = _run(tmp_path, {**ROUTE, "claims": claims})
    assert result.exit_code == 2 and "claims.0.condition: 'x' is not a condition" in result.stderr
    claims = [{"better": "klt", "than": "odometry", "metric": "success"}]
    result = _run(tmp_path, {**ROUTE, "claims": claims})
    assert result.exit_code == 2 and "claims.0.better: no method labelled 'klt'" in result.stderr
    assert not (tmp_path / "run").exists()


def test_a_grid_metric_in_a_robot_config_and_the_reverse_are_refused(
    tmp_path: Path, arena_manifest: Path
) -> None:
    claims = [{"better": "klt-sector", "than": "odometry", "metric": "ae"}]
    result = _run(tmp_path, {**ROUTE, "claims": claims})
    assert result.exit_code == 2
    refused = "claims.0.metric: 'ae' is a metric of grid runs; route runs' claims take success"
    assert refused in result.stderr
    claims = [{"better": "warping", "than": "random", "metric": "ahc", "condition": "posters"}]
    result = _run(tmp_path, {**TINY, "claims": claims})
    assert result.exit_code == 2 and "claims.0.metric: 'ahc' is a metric of grid" in result.stderr
    claims = [{"better": "warping", "than": "warping-coarse", "metric": "success",
               "condition": "arena-arena"}]  # fmt: skip
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, claims=claims))
    assert result.exit_code == 2
    assert "claims.0.metric: 'success' is a metric of robot (route, closed-loop) runs" in (
        result.stderr
    )
    claims = [{"better": "warping", "than": "warping-coarse", "metric": "ae"}]
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, claims=claims))
    assert result.exit_code == 2 and "claims.0.condition: give the condition" in result.stderr
    assert not (tmp_path / "run").exists()


def test_closed_loop_trials_are_clustered_by_goal_when_there_are_several() -> None:
    """Trials to one goal share its snapshot: with several goals the goal is the cluster,
    with one the start (the summary table's rule)."""
    rows = []
    for goal in (0, 1, 2):
        for start in range(4):
            for method, success in (("a", 1.0), ("b", float(start == 0))):
                rows.append({"method": method, "condition": "lab", "unit": f"g{goal}/s{start}",
                             "world": 0, "group": goal, "final_error_m": 0.1,
                             "success": success})  # fmt: skip
    trials = pd.DataFrame(rows)
    claim = ClaimEntry(better="a", than="b", metric="success")
    values, labels = trial_difference(claim, trials)
    assert values.sum() == 9 and len(np.unique(labels, axis=0)) == 3
    one_goal = trials[trials["group"] == 1]
    values, labels = trial_difference(claim, one_goal)
    assert len(values) == 4 and len(np.unique(labels, axis=0)) == 4
    equal = trial_difference(claim.model_copy(update={"metric": "final_error"}), trials)[0]
    assert not equal.any()


def test_the_guides_robot_claims_are_a_valid_closed_loop_section() -> None:
    """The guide's robot example (docs/guide/uncertainty.md) reads as a closed-loop config's."""
    from homebench.experiments.closed_loop.config import ClosedLoopConfig

    text = (Path(__file__).parents[1] / "docs" / "guide" / "uncertainty.md").read_text()
    section = text.split("**Your own claims.**")[1]
    block = section.split("```yaml\n")[2].split("```")[0]
    config = ClosedLoopConfig.model_validate(
        {**TINY, "output": "x", "styles": ["posters", "lab"], "controls": ["random"],
         "methods": [{"method": "warping"}, {"method": "alv"}], **yaml.safe_load(block)}
    )  # fmt: skip
    assert [c.metric for c in config.claims] == ["success", "final_error"]
    assert config.claims[1].condition == "lab" and config.claims[1].margin == 0.05


def test_a_route_run_records_its_claims_before_the_trials(tmp_path: Path) -> None:
    """One short drive: the claim is stamped before the trial and tested on it."""
    from test_route_experiment import SHORT

    claims = [{"better": "klt-sector", "than": "odometry", "metric": "final_error"}]
    result = _run(tmp_path, {**SHORT, "claims": claims})
    assert result.exit_code == 0, result.output
    recorded = json.loads((tmp_path / "run" / "config.resolved.json").read_text())["claims"]
    assert recorded[0]["results_before"] == 0 and recorded[0]["stated"]
    found = CliRunner().invoke(main, ["findings", str(tmp_path / "run")])
    assert found.exit_code == 0, found.output
    rows = {row[1]: row for row in _tables(found.stdout)[0]}
    claim = rows["klt-sector beats odometry in final_error over all trials"]
    assert claim[5] == "1" and claim[-1].endswith("before any result")


def test_a_claim_may_name_a_method_that_one_entry_runs() -> None:
    import pytest
    from pydantic import ValidationError

    from homebench.claim_spec import with_labels
    from homebench.experiments.closed_loop.config import ClosedLoopConfig

    claims = [{"better": "warping", "than": "random", "metric": "success"}]
    one = {**TINY, "output": "x", "methods": [{"method": "warping", "label": "w1"}]}
    config = ClosedLoopConfig.model_validate({**one, "claims": claims})
    names = {label: name for label, name, _ in config.method_points()}
    assert with_labels(config.claims[0], names).better == "w1"
    assert with_labels(config.claims[0], names).than == "random"  # a control: its label
    two = {**one, "methods": [*one["methods"], {"method": "warping", "label": "w2"}]}
    with pytest.raises(ValidationError, match=r"claims.0.better: 2 method entries run warping"):
        ClosedLoopConfig.model_validate({**two, "claims": claims})
    same = [{"better": "warping", "than": "w1", "metric": "success"}]
    with pytest.raises(ValidationError, match="name the same method entry 'w1'"):
        ClosedLoopConfig.model_validate({**one, "claims": same})
