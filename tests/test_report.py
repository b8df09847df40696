"""`homebench report`: the PDF, the figures and the HTML / Markdown reports of a run folder."""

from __future__ import annotations

import json
import math
import re
import shutil
from datetime import datetime
from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import pypdf
import pytest
from click.testing import CliRunner
from test_report_runs import STARTED, FakeMethod, real_arena_run, write_fake_run

from homebench.cli import main
from homebench.errors import DataError
from homebench.report.document import write_report
from homebench.report.pages import MAX_WARNINGS, PAGE_LINES, warning_pages

METHODS = [FakeMethod("warping", 20.0), FakeMethod("mine", 90.0, frozenset({(0, 0)}))]
CONDITIONS = ("orig-orig", "orig-day")
#: after the title: the headline and band tables; with two or more conditions the heat maps
#: (AHC, and as "mine" abstains the AHC with a missing estimate as 90 deg and the share without
#: an estimate; RR, mean AE); AHC and RR of all conditions side by side and the time per call;
#: then per condition its fields and its AE maps (two goals a figure)
TABLE_PAGES = 2
HEATMAP_PAGES = 5
PAGES_PER_RUN = 3
PAGES_PER_CONDITION = 2
#: the appendix: definitions (3 pages), the config and the environment (1 page each)
APPENDIX_PAGES = 5


@pytest.fixture
def fake_run(tmp_path: Path) -> Path:
    """One condition, two goals: the smallest run that has every kind of page."""
    return write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS[:1], name="fake-run")


def _text(pdf: Path, page: int) -> str:
    return pypdf.PdfReader(pdf).pages[page].extract_text()


@pytest.mark.slow  # CI time: test_report_document's tests write and read whole reports
def test_report_writes_pdf_tables_and_figures(tmp_path: Path) -> None:
    fake_run = write_fake_run(tmp_path / "run", METHODS, conditions=CONDITIONS, name="fake-run")
    outcome = write_report(fake_run, ["pdf", "html", "md"], max_goals=1)
    pages = 1 + TABLE_PAGES + HEATMAP_PAGES + PAGES_PER_RUN + len(CONDITIONS) * PAGES_PER_CONDITION
    pages += APPENDIX_PAGES
    folder = fake_run / "report"
    pdf = folder / "report.pdf"
    assert outcome.warnings == []
    assert set(outcome.files) >= {pdf, folder / "report.html", folder / "report.md"}
    reader = pypdf.PdfReader(pdf)
    assert len(reader.pages) == pages
    assert reader.metadata.title == "homebench report: fake-run"
    assert reader.metadata.creation_date == datetime.fromisoformat(STARTED)
    title = _text(pdf, 0)
    for expected in ("homebench report: fake-run", "2024-05-06 07:08:09 UTC", "method warping",
                     "database day: db-day", "orig-orig, orig-day", "testhost"):  # fmt: skip
        assert expected in title
    summary = _text(pdf, 1)
    assert "mean AE [deg]" in summary and "90.00" in summary and "20.00" in summary
    bands = _text(pdf, 2)
    # every pair of the fake grid is in the nearest band (below 1.2 m); "mine" abstains on 2
    # of its 38 pairs there
    assert "Results per band of distance" in bands and "rotation flips [%]" in bands
    assert "orig-orig mine 0-1.2 m 38 0.000 [0.000, 0.000] 0.000 5.3 [5.3, 5.3]" in bands
    # the per-goal figures come last, grouped by condition, in the config's order
    first_per_goal = 1 + TABLE_PAGES + HEATMAP_PAGES + PAGES_PER_RUN
    assert "Home-vector fields, orig-orig (current: db-orig" in _text(pdf, first_per_goal)
    last_figure = pages - 1 - APPENDIX_PAGES
    assert "orig-day (current: db-orig, goal: db-day)" in _text(pdf, last_figure)
    figures = sorted((folder / "figures").glob("*.png"))
    assert len(figures) == pages - 1 - TABLE_PAGES - APPENDIX_PAGES
    assert figures == sorted(p for p in outcome.files if p.suffix == ".png")
    for path in figures:
        image = cv2.imread(str(path))
        assert image is not None and image.shape[0] > 300 and image.std() > 10, path.name
    html = (folder / "report.html").read_text()
    markdown = (folder / "report.md").read_text()
    for path in figures:
        assert f'src="figures/{path.name}"' in html and f"(figures/{path.name})" in markdown
    assert (folder / "tables" / "summary.tex").is_file()


# CI time: two whole reports (15-28 s); fresh clones' .ci/run took 942-1020 s this stop. The
# report's inputs are covered in the default selection by test_report_reuse's key tests
@pytest.mark.slow
def test_two_reports_of_a_run_are_byte_identical(fake_run: Path, tmp_path: Path) -> None:
    first = write_report(fake_run, ["pdf", "html", "md"], tmp_path / "a", max_goals=1).files
    second = write_report(fake_run, ["pdf", "html", "md"], tmp_path / "b", max_goals=1).files
    assert [p.relative_to(tmp_path / "a") for p in first] == [
        p.relative_to(tmp_path / "b") for p in second
    ]
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


def test_only_some_goals_are_drawn_when_asked(fake_run: Path) -> None:
    outcome = write_report(fake_run, ["md"], max_goals=1)
    names = [p.name for p in outcome.files if p.suffix == ".png"]
    assert sorted(n for n in names if "_fields_" in n) == ["orig-orig_fields_1.png"]
    assert "(1 of 2 goals shown)" in (fake_run / "report" / "report.md").read_text()
    assert not (fake_run / "report" / "report.pdf").exists()


@pytest.mark.parametrize(
    ("flags", "drawn", "note"),
    [
        ((), {(1, 2), (3, 4)}, "2 of 3 goals (--max-goals)"),  # the default
        (("--max-goals", "1"), {(1, 2)}, "1 of 3 goals (--max-goals)"),
        (("--max-goals", "0"), {(1, 2), (2, 3), (3, 4)}, "every goal"),
    ],
)
def test_max_goals_bounds_the_per_goal_appendix(
    tmp_path: Path, flags: tuple[str, ...], drawn: set[tuple[int, int]], note: str
) -> None:
    goals = ((1, 2), (2, 3), (3, 4))
    run = write_fake_run(tmp_path / "run", METHODS, goals=goals, conditions=CONDITIONS[:1])
    result = CliRunner().invoke(main, ["report", str(run), "--format", "md", *flags])
    assert result.exit_code == 0, result.output
    markdown = (run / "report" / "report.md").read_text()
    fields = " ".join(re.findall(r"\*Figure \d+\. Home-vector fields, [^*]*\*", markdown))
    assert {goal for goal in goals if str(goal) in fields} == drawn
    assert ("goals shown" in fields) == (len(drawn) < len(goals))
    assert f"home-vector fields and AE maps of {note} per condition" in markdown


def test_missing_and_corrupt_jobs_get_a_warning_page(fake_run: Path) -> None:
    (fake_run / "jobs" / "orig-orig_mine_2_3.json").unlink()
    (fake_run / "jobs" / "orig-orig_warping_1_2.json").write_text('{"key": "orig-orig_wa')
    outcome = write_report(fake_run)
    assert len(outcome.warnings) == 2
    assert any("jobs/orig-orig_mine_2_3.json (orig-orig, mine, goal (2, 3))" in w
               for w in outcome.warnings)  # fmt: skip
    pdf = fake_run / "report" / "report.pdf"
    warning = _text(pdf, 1)
    assert "Warning: missing job results" in warning
    assert "orig-orig_mine_2_3.json" in warning and "orig-orig_warping_1_2.json" in warning
    assert "missing or corrupt job files: 2" in _text(pdf, 0)
    # each goal keeps one method: both goals are still drawn, after the warning page
    figure_pages = PAGES_PER_RUN + PAGES_PER_CONDITION
    assert len(pypdf.PdfReader(pdf).pages) == 2 + TABLE_PAGES + figure_pages + APPENDIX_PAGES


def test_a_folder_that_is_no_run_or_has_no_results_is_a_data_error(
    fake_run: Path, tmp_path: Path
) -> None:
    with pytest.raises(DataError, match="no such run folder"):
        write_report(tmp_path / "nowhere")
    broken = tmp_path / "broken"
    shutil.copytree(fake_run, broken)
    (broken / "config.resolved.json").write_text("{not json")
    with pytest.raises(DataError, match=r"config\.resolved\.json: corrupt"):
        write_report(broken)
    for job in (fake_run / "jobs").glob("*.json"):
        job.unlink()
    with pytest.raises(DataError, match=r"no job results to report on \(missing: jobs/"):
        write_report(fake_run)


# CI time: processes of docs/tutorials: tour.md reports a run and compares two, robots.md runs
# homebench report
@pytest.mark.slow
def test_cli_report_and_compare_on_a_real_run(tmp_path: Path, arena_manifest: Path) -> None:
    run = real_arena_run(tmp_path / "a", arena_manifest)
    runner = CliRunner()
    result = runner.invoke(
        main, ["report", str(run), "--format", "pdf", "--format", "html", "--max-goals", "1"]
    )
    assert result.exit_code == 0, result.output
    printed = [Path(line) for line in result.stdout.splitlines()]
    assert run / "report" / "report.pdf" in printed and run / "report" / "report.html" in printed
    assert all(p.is_file() for p in printed)
    pdf = pypdf.PdfReader(run / "report" / "report.pdf")
    assert len(pdf.pages) == 1 + TABLE_PAGES + PAGES_PER_RUN + PAGES_PER_CONDITION + APPENDIX_PAGES

    other = tmp_path / "b"
    shutil.copytree(run, other)
    plan = json.loads((other / "plan.json").read_text())
    (other / "jobs" / f"{plan[0]['key']}.json").unlink()
    result = runner.invoke(
        main, ["report", str(other), "--out", str(tmp_path / "rep"), "--format", "md",
               "--max-goals", "1"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert f"missing job result jobs/{plan[0]['key']}.json" in result.stderr
    result = runner.invoke(main, ["compare", str(run), str(other)])
    assert result.exit_code == 0, result.output
    assert "mean_ae_deg" in result.stdout and "min-warping" in result.stdout

    result = runner.invoke(main, ["report", str(tmp_path / "nowhere")])
    assert result.exit_code == 2
    assert result.stderr.strip() == f"homebench: error: {tmp_path / 'nowhere'}: no such run folder"


def test_long_warning_lists_continue_on_more_pages_and_are_capped() -> None:
    warnings = [f"jobs/{k:04d}.json (a-a, m, goal (0, {k}))" for k in range(MAX_WARNINGS + 50)]
    pages = warning_pages(warnings)
    texts = ["\n".join(t.get_text() for t in fig.texts) for fig in pages]
    for fig in pages:
        plt.close(fig)
    assert len(pages) == math.ceil((MAX_WARNINGS + 4) / PAGE_LINES)
    assert "(continued)" in texts[1]
    joined = "\n".join(texts)
    assert "jobs/0199.json" in joined and "jobs/0200.json" not in joined
    assert texts[-1].rstrip().endswith("... and 50 more")
