"""The host's load while a run timed its jobs: recorded in environment.json, said beside the
report's timing columns and figure; old run folders, which did not record it, stay readable."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from pydantic import ValidationError

from homebench.evaluation.provenance import load_average, record_load_end
from homebench.report.environment_record import EnvironmentRecord
from homebench.report.host_load import load_note

RECORDED = {"start_1min": 0.52, "end_1min": 3.9, "jobs_timed": 40, "jobs_reused": 0}


def test_the_note_gives_the_load_at_start_and_end_and_the_cpus() -> None:
    note = load_note({"load": RECORDED, "cpu": {"count": 2}})
    assert "0.52 at the start and 3.90 at the end" in note and "2 CPUs" in note
    assert "all 40 jobs" in note and "above the CPU count" in note


def test_the_note_says_what_it_does_not_know() -> None:
    reused = load_note({"load": {**RECORDED, "jobs_timed": 3, "jobs_reused": 37}})
    assert "3 of 40 jobs" in reused and "37 in earlier calls, under a load not recorded" in reused
    interrupted = load_note({"load": {"start_1min": 0.5}, "cpu_count": 4})
    assert "end not recorded" in interrupted and "4 CPUs" in interrupted
    assert "not recorded" in load_note({})  # a run folder of an older homebench


def test_the_environment_record_checks_the_load_and_accepts_old_folders() -> None:
    assert EnvironmentRecord.model_validate({"load": RECORDED}).load.end_1min == 3.9
    assert EnvironmentRecord.model_validate({}).load is None
    assert EnvironmentRecord.model_validate({"load": {"start_1min": 1}}).load.start_1min == 1
    with pytest.raises(ValidationError):
        EnvironmentRecord.model_validate({"load": {"start_1min": "high"}})


def test_the_end_of_a_run_call_is_added_to_its_environment_record(tmp_path: Path) -> None:
    path = tmp_path / "environment.json"
    path.write_text(json.dumps({"host": "h", "load": {"start_1min": 0.25}}))
    record_load_end(tmp_path, jobs_timed=5, jobs_reused=2)
    load = json.loads(path.read_text())["load"]
    assert load["start_1min"] == 0.25 and load["jobs_timed"] == 5 and load["jobs_reused"] == 2
    assert load["end_1min"] == pytest.approx(load_average(), abs=5.0)
