"""A report is rebuilt when something it is made from changed, and only then."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_report_runs import FakeMethod, write_fake_run

from homebench.report import document, reuse
from homebench.report.document import write_report

METHODS = [FakeMethod("warping", 20.0), FakeMethod("mine", 90.0, frozenset({(0, 0)}))]


@pytest.fixture
def builds(monkeypatch: pytest.MonkeyPatch) -> list[Path]:
    """The run folders of the reports built (not reused) from now on."""
    built: list[Path] = []
    real = document._build_report

    def counted(run_dir: Path, *args: object) -> document.ReportOutcome:
        built.append(run_dir)
        return real(run_dir, *args)

    monkeypatch.setattr(document, "_build_report", counted)
    return built


def test_an_unchanged_run_keeps_its_report(tmp_path: Path, builds: list[Path]) -> None:
    run = write_fake_run(tmp_path / "run", METHODS)
    first = write_report(run, ["pdf", "md"], max_goals=1)
    pdf = run / "report" / "report.pdf"
    written = pdf.stat().st_mtime_ns
    # a rerun renews the stamps of environment.json (its start and command) and the tables
    environment = json.loads((run / "environment.json").read_text())
    environment |= {"started": "2030-01-01T00:00:00+00:00", "command": ["homebench", "run"]}
    (run / "environment.json").write_text(json.dumps(environment))
    second = write_report(run, ["pdf", "md"], max_goals=1)
    assert builds == [run]
    assert second == first and pdf.stat().st_mtime_ns == written
    assert (run / "report" / reuse.KEY_FILE).is_file()


def test_a_changed_input_argument_or_lost_file_rebuilds(tmp_path: Path, builds: list[Path]) -> None:
    run = write_fake_run(tmp_path / "run", METHODS)
    write_report(run, ["md"], max_goals=1)
    write_report(run, ["md"], max_goals=2)  # another argument
    assert len(builds) == 2
    (run / "report" / "report.md").unlink()  # an output gone
    write_report(run, ["md"], max_goals=2)
    assert len(builds) == 3
    job = sorted((run / "jobs").iterdir())[0]
    job.unlink()  # an input changed: the report now warns about it
    outcome = write_report(run, ["md"], max_goals=2)
    assert len(builds) == 4
    assert len(outcome.warnings) == 1 and job.name in outcome.warnings[0]
    assert write_report(run, ["md"], max_goals=2) == outcome
    assert len(builds) == 4
    environment = json.loads((run / "environment.json").read_text())
    (run / "environment.json").write_text(json.dumps({**environment, "host": "other"}))
    write_report(run, ["md"], max_goals=2)  # what the run recorded, not a stamp
    assert len(builds) == 5


def test_the_key_reads_no_features_hidden_files_or_the_report(tmp_path: Path) -> None:
    run = write_fake_run(tmp_path / "run", METHODS)
    folder = run / "report"
    key = reuse.report_key(run, folder, {"formats": ["pdf"]})
    for name in ("features/x.npz", ".homebench.lock", "report/report.pdf"):
        (run / name).parent.mkdir(parents=True, exist_ok=True)
        (run / name).write_bytes(b"anything")
    assert reuse.report_key(run, folder, {"formats": ["pdf"]}) == key
    assert reuse.report_key(run, folder, {"formats": ["md"]}) != key
    (run / "plan.json").write_text((run / "plan.json").read_text() + " ")
    assert reuse.report_key(run, folder, {"formats": ["pdf"]}) != key
