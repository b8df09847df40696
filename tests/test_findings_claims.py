"""`homebench findings` on any run: the findings it can test, the others with the reason; roles
by label or method name; runs pooled; the runs' own claims, stated before the results."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import arena_config, run_config
from test_report_runs import FakeMethod, write_fake_run

from homebench.cli import main

GOALS5 = ((0, 0), (1, 2), (2, 3), (3, 4), (0, 4))


def _run(folder: Path, labels: dict[str, float], conditions=("original-original",),
         goals=GOALS5, world: str = "", names: dict[str, str] | None = None,
         claims: list[dict] | None = None) -> Path:  # fmt: skip
    """A fake grid run: each label's AE is its offset (deg) everywhere; ``names`` gives a
    label's method name, ``claims`` the recorded config's claims."""
    methods = [FakeMethod(label, offset) for label, offset in labels.items()]
    run = write_fake_run(folder, methods, goals, conditions=conditions, world=world)
    for job in (run / "jobs").glob("*.json"):
        record = json.loads(job.read_text())
        record["method_name"] = (names or {}).get(record["method"], "fake")
        job.write_text(json.dumps(record))
    if claims is not None:
        config = json.loads((run / "config.resolved.json").read_text())
        (run / "config.resolved.json").write_text(json.dumps(config | {"claims": claims}))
    return run


def _tables(output: str) -> tuple[list[list[str]], list[list[str]]]:
    """The rows (cells) of the findings table and of the not-tested table."""
    tested, _, untested = output.partition("Not tested")

    def rows(text: str) -> list[list[str]]:
        lines = [line for line in text.splitlines() if line.startswith("|")][2:]
        return [[cell.strip() for cell in line.strip("|").split("|")] for line in lines]

    return rows(tested), rows(untested)


def test_a_one_condition_run_tests_its_findings_and_lists_the_rest(tmp_path: Path) -> None:
    """P, PN and W under original-original only (the command refused it: no
    'original-arboreal'); driven as a user would, in a process of its own."""
    run = _run(tmp_path / "bielefeld", {"P": 5.0, "PN": 12.0, "W": 25.0})
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "findings", str(run)],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    tested, untested = _tables(done.stdout)
    statements = {row[1] for row in tested}
    assert "P errs less than W under original-original (P's AHC above W's)" in statements
    assert all("arboreal" not in s and "day" not in s for s in statements)
    reasons = {row[1]: row[2] for row in untested}
    assert reasons["P<W AE original-day"] == "no condition 'original-day'"
    assert reasons["day hits W harder"] == "no condition 'original-day'"
    assert "far range: W<P" in reasons
    assert not any(key.startswith("P<W AE original-original") for key in reasons)
    goals = {row[-3] for row in tested}  # the goals each verdict rests on
    assert goals == {"5"}


def test_no_testable_finding_exits_2_with_the_reasons(tmp_path: Path) -> None:
    run = _run(tmp_path / "mine", {"alpha": 5.0, "beta": 10.0}, conditions=("a-a",))
    result = CliRunner().invoke(main, ["findings", str(run)])
    assert result.exit_code == 2
    _, untested = _tables(result.stdout)
    assert {row[2] for row in untested} >= {"no method labelled 'P', 'W'"}
    assert "none of the findings could be tested" in result.stderr
    shown = " ".join(CliRunner().invoke(main, ["findings", "--help"]).stdout.split())
    assert "P<W AE original-day: P, W under day" in shown  # from the findings' definitions
    assert "day hits W harder: W, P under original, day" in shown


def test_roles_by_method_name_and_label(tmp_path: Path) -> None:
    names = {"mine": "sift", "mine-pn": "sift", "theirs": "warping"}
    run = _run(tmp_path / "r", {"mine": 5.0, "mine-pn": 9.0, "theirs": 20.0}, names=names)
    result = CliRunner().invoke(
        main, ["findings", str(run), "--role", "P=mine", "--role", "PN=mine-pn",
               "--role", "W=warping"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    tested, _ = _tables(result.stdout)
    assert "mine errs less than theirs under original-original (P's AHC above W's)" in {
        row[1] for row in tested
    }
    ambiguous = CliRunner().invoke(main, ["findings", str(run), "--role", "P=sift"])
    assert ambiguous.exit_code == 2
    assert "--role P=sift: 2 method entries run sift (mine, mine-pn)" in ambiguous.stderr
    absent = CliRunner().invoke(main, ["findings", str(run), "--role", "W=wraping"])
    assert absent.exit_code == 2 and "--role W=wraping: no method" in absent.stderr


def test_pooled_runs_rest_on_the_union_of_goals(tmp_path: Path) -> None:
    """Five goals per run: no sign-flip p below 2 / 2**5; pooled, ten goals go below it."""
    runs = [
        _run(tmp_path / name, {"P": 5.0, "PN": 12.0, "W": 25.0}, world=name) for name in ("a", "b")
    ]
    alone = CliRunner().invoke(main, ["findings", str(runs[0])])
    row = next(r for r in _tables(alone.stdout)[0] if r[1].startswith("P errs less than W"))
    assert row[-3] == "5" and row[-1] == "not significant"
    assert float(row[-2]) >= 2 / 2**5  # Holm over the run's findings: higher still
    pooled = CliRunner().invoke(
        main, ["findings", *map(str, runs), "--place", "a=room", "--place", "b=room"]
    )
    assert pooled.exit_code == 0, pooled.output
    rows = [r for r in _tables(pooled.stdout)[0] if r[1].startswith("P errs less than W")]
    assert len(rows) == 2 and {r[0] for r in rows} == {"room"}
    assert {(r[-3], r[-1]) for r in rows} == {("10", "holds")}
    assert max(float(r[-2]) for r in rows) < 2 / 2**5  # after Holm
    everything = CliRunner().invoke(main, ["findings", *map(str, runs), "--pool", "all"])
    assert _tables(everything.stdout)[0] == [["all", *r[1:]] for r in _tables(pooled.stdout)[0]]


CLAIMS = [
    {"better": "alpha", "than": "beta", "metric": "ae", "condition": "a-a",
     "stated": "2026-01-02T03:04:05+00:00", "results_before": 0},
    {"better": "alpha", "than": "beta", "metric": "ahc", "condition": "a-a",
     "band": [0.0, 0.7], "margin": 0.05, "stated": "2026-01-03T00:00:00+00:00",
     "results_before": 12},
    {"better": "beta", "than": "alpha", "metric": "rr", "condition": "a-a"},
]  # fmt: skip


def test_a_runs_claims_are_tested_with_the_papers_findings(tmp_path: Path) -> None:
    goals = (*GOALS5, (3, 0), (1, 0))  # seven goals: 2 / 2**7 < 0.05 / 3
    run = _run(tmp_path / "own", {"alpha": 5.0, "beta": 40.0}, ("a-a",), goals, claims=CLAIMS)
    result = CliRunner().invoke(main, ["findings", str(run)])
    assert result.exit_code == 0, result.output
    tested, untested = _tables(result.stdout)
    by_claim = {row[1]: row for row in tested}
    ae = by_claim["alpha beats beta in ae under a-a"]
    # goals, p (Holm: second smallest of 3, 2 x 2 / 2**7), verdict, stated
    assert ae[3] == "35.00" and ae[-4:-1] == ["7", "0.031", "holds"]
    assert ae[-1] == "2026-01-02 03:04 UTC, before any result"
    ahc = by_claim["alpha beats beta in ahc under a-a (0-0.7 m, by more than 0.05)"]
    assert ahc[-1] == "2026-01-03 00:00 UTC, after 12 job result(s)"
    assert ahc[-2] == "holds"
    rr = by_claim["beta beats alpha in rr under a-a"]
    assert rr[-1] == "not recorded by a run" and rr[-2] == "opposite"  # 40 deg off fails more
    assert len(tested) == 3 and untested  # no seed 001 finding: P and W are absent


def test_a_claim_naming_a_missing_label_is_a_config_error_before_any_job(
    tmp_path: Path, arena_manifest: Path
) -> None:
    claims = [{"better": "warping", "than": "warpnig", "metric": "ae", "condition": "arena-arena"}]
    config = arena_config(tmp_path, arena_manifest, claims=claims)
    result = run_config(tmp_path, config)
    assert result.exit_code == 2
    assert "claims.0.than: no method labelled 'warpnig'" in result.stderr
    assert not (tmp_path / "run").exists()
    claims[0] |= {"than": "warping-coarse", "condition": "arena-day"}
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, claims=claims))
    assert result.exit_code == 2 and "claims.0.condition: 'arena-day'" in result.stderr
    claims[0] = {"beter": "warping", "than": "warping-coarse", "metric": "ae", "condition": "x"}
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, claims=claims))
    assert result.exit_code == 2 and "unknown key 'beter' (did you mean 'better'?)" in result.stderr
    assert "claims[0]" in result.stderr and not (tmp_path / "run").exists()


@pytest.mark.slow
def test_claims_are_recorded_before_the_jobs_and_a_later_one_reads_as_later(
    tmp_path: Path, arena_manifest: Path
) -> None:
    first = {"better": "warping", "than": "warping-coarse", "metric": "ae",
             "condition": "arena-arena"}  # fmt: skip
    config = arena_config(tmp_path, arena_manifest, claims=[first])
    assert run_config(tmp_path, config).exit_code == 0
    recorded = json.loads((tmp_path / "run" / "config.resolved.json").read_text())["claims"]
    assert recorded[0]["results_before"] == 0 and recorded[0]["stated"]
    later = first | {"metric": "ahc90"}
    config["claims"] = [first, later]
    refused = run_config(tmp_path, config)
    assert refused.exit_code == 2 and "--update" in refused.stderr
    assert run_config(tmp_path, config, "--update").exit_code == 0
    again = json.loads((tmp_path / "run" / "config.resolved.json").read_text())["claims"]
    assert again[0] == recorded[0]
    assert again[1]["results_before"] == 4 and again[1]["stated"] >= recorded[0]["stated"]
    result = CliRunner().invoke(main, ["findings", str(tmp_path / "run")])
    assert result.exit_code == 0, result.output
    assert "after 4 job result(s)" in result.stdout


def test_a_config_without_claims_resolves_as_before_claims_existed(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """A run folder recorded before claims existed (no 'claims' key) still belongs to its
    config: re-running it must not need --update."""
    from homebench.config import RunConfig
    from homebench.evaluation.executors import Execution
    from homebench.evaluation.isolation import Limits
    from homebench.evaluation.provenance import resolve_config
    from homebench.evaluation.run_folder import check_owner

    config = RunConfig.model_validate(arena_config(tmp_path, arena_manifest))
    resolved = resolve_config(config, Execution(), Limits(), [])
    before = {key: value for key, value in resolved.items() if key != "claims"}
    (tmp_path / "config.resolved.json").write_text(json.dumps(before))
    check_owner(tmp_path, resolved, take_over=False)  # ConfigError: "claims: null there"


def test_the_guides_claims_are_a_valid_config_section() -> None:
    """The guide's example (docs/guide/uncertainty.md) reads as a run config's claims."""
    import yaml

    from homebench.config import RunConfig

    text = (Path(__file__).parents[1] / "docs" / "guide" / "uncertainty.md").read_text()
    section = text.split("**Your own claims.**")[1]
    block = section.split("```yaml\n")[1].split("```")[0]
    methods = [{"method": "sift", "label": label} for label in ("P", "W")]
    methods += [{"method": "min-warping"}, {"method": "warping"}]
    config = RunConfig.model_validate(
        {"output": "x", "databases": {"original": "synth-original", "day": "synth-day"},
         "conditions": ["original-original", "original-day"], "goals": [[1, 1]],
         "methods": methods, **yaml.safe_load(block)}
    )  # fmt: skip
    assert [c.metric for c in config.claims] == ["ae", "ahc"]
    assert config.claims[1].band == (0.0, 1.2) and config.claims[1].margin == 0.05


def test_pooling_by_style_and_what_the_options_refuse(tmp_path: Path) -> None:
    """--pool style pools runs of one generated style; a run of recorded databases has none;
    a --place naming no run, an unknown role: exit 2 naming the option."""
    runs = []
    for name in ("a", "b"):
        run = _run(tmp_path / name, {"P": 5.0, "PN": 12.0, "W": 25.0}, world=name)
        config = json.loads((run / "config.resolved.json").read_text())
        config["databases"]["original"] = {"world": {"style": "lab", "seed": len(runs)}}
        (run / "config.resolved.json").write_text(json.dumps(config))
        runs.append(run)
    pooled = CliRunner().invoke(main, ["findings", *map(str, runs), "--pool", "style"])
    assert pooled.exit_code == 0, pooled.output
    assert {(row[0], row[-3]) for row in _tables(pooled.stdout)[0]} == {("lab", "10")}
    recorded = _run(tmp_path / "c", {"P": 5.0, "W": 25.0}, world="c")
    refused = [
        (["--pool", "style"], "--pool style: run c holds no generated world of one style"),
        (["--place", "d=room"], "--place d=...: no such run (runs: a, b, c)"),
        (["--role", "Q=P"], "--role Q: no such role"),
        (["--role", "P"], "--role 'P': expected NAME=VALUE"),
    ]
    for options, message in refused:
        result = CliRunner().invoke(main, ["findings", *map(str, [*runs, recorded]), *options])
        assert result.exit_code == 2 and message in result.stderr, (options, result.output)


def test_route_runs_name_seed_000s_method_by_role(tmp_path: Path) -> None:
    from test_report_routes import write_route_run

    write_route_run(tmp_path / "run")
    run = str(tmp_path / "run")
    by_name = CliRunner().invoke(main, ["findings", run, "--role", "KLT=klt-sector"])
    assert by_name.exit_code == 0, by_name.output
    header = next(line for line in by_name.stdout.splitlines() if line.startswith("| place"))
    assert "trials" in [cell.strip() for cell in header.split("|")]  # the units: trials
    absent = CliRunner().invoke(main, ["findings", run, "--role", "KLT=warping"])
    assert absent.exit_code == 2
    assert "no finished trial of a method labelled or named 'warping'" in absent.stdout
    grid_role = CliRunner().invoke(main, ["findings", run, "--role", "P=sift"])
    assert grid_role.exit_code == 2 and "--role P: a role of seed 001's grid" in grid_role.stderr
