"""`homebench report` of a route-homing run: PDF, tables, figures, warnings and the CLI.

The run folder is written by hand (config, environment, one trial file per planned trial
with straight-line poses and known errors), so every number in the report is known.
"""

from __future__ import annotations

import json
from datetime import datetime
from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pypdf
import pytest
from click.testing import CliRunner

from homebench.cli import main
from homebench.config import MethodEntry
from homebench.errors import DataError
from homebench.experiments.route.config import RouteConfig
from homebench.experiments.route.experiment import RouteJob, RouteTrial, plan_trials
from homebench.report.document import write_report
from homebench.report.route.figures import RouteResult, route_error_figure, route_figure
from homebench.report.style import method_styles, report_style

STARTED = "2024-05-06T07:08:09+00:00"
HOME = (1.7, 1.8)
#: (visual error, odometry error) in metres of each trial, by name.
ERRORS = {
    "line-1m-r0": (0.004, 0.05),
    "line-1m-r1": (0.006, 0.09),
    "line-1m-r2": (0.002, 0.07),
    "line-3m-r0": (0.011, 0.40),
    "line-3m-r1": (0.007, 0.20),
    "line-3m-r2": (0.030, 0.60),
}
#: title, the table per length, the table per trial, the error figure, one page per length,
#: the config and the environment
PAGES = 1 + 2 + 1 + 2 + 2


def _jobs() -> list[RouteJob]:
    config = _config(Path("run"))  # the output folder is no part of a trial's key
    return [RouteJob(config, trial) for trial in plan_trials(config)]


def _config(run: Path) -> RouteConfig:
    return RouteConfig.model_validate(
        {
            "kind": "route",
            "name": "tiny-route",
            "output": str(run),
            "routes": [
                {"name": "line", "waypoints": [HOME, (1.7, 4.8)], "lengths": [1, 3], "repeats": 3}
            ],
        }
    )


def _trial_record(job: RouteJob, k: int) -> dict:
    """Straight out along +y for the trial's length, back home with known misses."""
    trial: RouteTrial = job.trial
    visual, odometry = ERRORS[trial.name]
    y = HOME[1] + np.linspace(0.0, trial.length, 21)
    outbound = np.stack([np.full_like(y, HOME[0]), y, np.full_like(y, np.pi / 2)], axis=1)
    homing = outbound[::-1].copy()
    homing[-1, 0] += visual  # ends `visual` metres right of home
    back = outbound[::-1].copy()
    back[:, 0] += odometry * np.linspace(0.0, 1.0, len(back))  # drifts `odometry` to the right
    summary = {
        "trial": trial.name,
        "route": trial.route,
        "length_m": trial.length,
        "driven_m": trial.length,
        "frames": 21,
        "features": 300 + k,
        "features_home": 150,
        "min_shared": 80,
        "n_intermediate": 1 + k % 2,
        "visual_status": "reached" if k != 5 else "lost",
        "visual_steps": 30,
        "visual_error_m": visual,
        "visual_heading_error_deg": 0.5 * k,
        "odometry_error_m": odometry,
        "odometry_heading_error_deg": 3.0 + k,
        "odometry_drift_at_end_m": 0.01 * k,
    }
    return {
        "key": job.key,
        "trial": trial.name,
        "outbound": outbound.tolist(),
        "homing": homing.tolist(),
        "odometry": back.tolist(),
        "intermediate": [10, 5][: 1 + k % 2],
        "summary": summary,
    }


def write_route_run(run: Path) -> RouteConfig:
    """A finished route run of six trials (two lengths, three repeats) under ``run``."""
    config = _config(run)
    (run / "routes").mkdir(parents=True)
    (run / "config.resolved.json").write_text(json.dumps(config.model_dump(mode="json")))
    environment = {"config_file": "tiny.yaml", "host": "testhost", "platform": "Linux",
                   "cpu_count": 2, "versions": {"homebench": "0"}, "started": STARTED}  # fmt: skip
    (run / "environment.json").write_text(json.dumps(environment))
    for k, trial in enumerate(plan_trials(config)):
        job = RouteJob(config, trial)
        job.result_path(run).write_text(json.dumps(_trial_record(job, k)))
    return config


@pytest.fixture
def route_run(tmp_path: Path) -> Path:
    write_route_run(tmp_path / "run")
    return tmp_path / "run"


def _text(pdf: Path, page: int) -> str:
    return pypdf.PdfReader(pdf).pages[page].extract_text()


def _pixels_of(image: np.ndarray, colour: str) -> int:
    bgr = np.array([int(colour[k : k + 2], 16) for k in (5, 3, 1)])
    return int(np.sum(np.all(np.abs(image.astype(int) - bgr) < 40, axis=2)))


def test_route_report_has_title_tables_and_figures(route_run: Path) -> None:
    outcome = write_report(route_run, ["pdf", "html", "md"])
    folder = route_run / "report"
    pdf = folder / "report.pdf"
    assert outcome.warnings == []
    reader = pypdf.PdfReader(pdf)
    assert len(reader.pages) == PAGES
    assert reader.metadata.title == "homebench report: tiny-route"
    assert reader.metadata.creation_date == datetime.fromisoformat(STARTED)
    title = _text(pdf, 0)
    expected_lines = [
        "homebench report: tiny-route",
        "started: 2024-05-06 07:08:09 UTC",
        "route line: 2 waypoints, 3.00 m",
        "trials over the first 1, 3 m",
        "tracker: KltTracker defaults",
        "testhost",
        "6 of 6 planned trials",
        "reached home in 5 of 6 trials",
        "visual 0.65 cm, odometry 14.50 cm (max 3.00 and 60.00 cm)",
    ]
    for expected in expected_lines:
        assert expected in title
    assert "visual error mean" in _text(pdf, 1) and "line-3m-r2" in _text(pdf, 2)
    assert "Final position error against route length" in _text(pdf, 3)
    assert "line-1m-r0" in _text(pdf, 4) and "line-3m-r0" in _text(pdf, 5)

    figures = sorted((folder / "figures").glob("*.png"))
    assert [p.name for p in figures] == [
        "final_error.png",
        "trajectories_line-1m-r0_to_line-1m-r2.png",
        "trajectories_line-3m-r0_to_line-3m-r2.png",
    ]
    colour = method_styles(["klt-sector"])["klt-sector"].colour
    for path in figures:
        image = cv2.imread(str(path))
        assert image is not None and image.shape[0] > 300 and image.std() > 10, path.name
        assert _pixels_of(image, colour) > 200, path.name
    html = (folder / "report.html").read_text()
    markdown = (folder / "report.md").read_text()
    for path in figures:
        assert f'src="figures/{path.name}"' in html and f"(figures/{path.name})" in markdown
    assert "## Trajectories" in markdown and "odometry error [cm]" in markdown
    for name in ("routes", "routes_by_length"):
        for suffix in ("csv", "md", "tex"):
            assert (folder / "tables" / f"{name}.{suffix}").is_file()


def test_table_numbers_are_the_trial_files(route_run: Path) -> None:
    write_report(route_run, ["md"])
    tables = route_run / "report" / "tables"
    trials = pd.read_csv(tables / "routes.csv")
    summaries = [json.loads(p.read_text())["summary"] for p in sorted(route_run.glob("routes/*"))]
    expected = pd.DataFrame(summaries).set_index("trial").loc[trials["trial"]]
    assert list(trials["trial"]) == list(ERRORS)  # plan order
    assert np.allclose(trials["visual error [cm]"], 100 * expected["visual_error_m"])
    assert np.allclose(trials["odometry error [cm]"], 100 * expected["odometry_error_m"])
    assert np.allclose(trials["visual heading error [deg]"], expected["visual_heading_error_deg"])
    assert np.allclose(
        trials["odometry heading error [deg]"], expected["odometry_heading_error_deg"]
    )
    assert np.allclose(trials["route length [m]"], expected["driven_m"])
    assert list(trials["intermediate positions"]) == list(expected["n_intermediate"])
    assert list(trials["features tracked"]) == list(expected["features"])
    assert list(trials["visual status"]) == list(expected["visual_status"])

    by_length = pd.read_csv(tables / "routes_by_length.csv")
    assert list(by_length["length [m]"]) == [1.0, 3.0]
    assert list(by_length["trials"]) == [3, 3] and list(by_length["reached home"]) == [3, 2]
    visual = np.array(list(ERRORS.values()))[:, 0].reshape(2, 3)
    odometry = np.array(list(ERRORS.values()))[:, 1].reshape(2, 3)
    assert np.allclose(by_length["visual error mean [cm]"], np.round(100 * visual.mean(1), 2))
    assert np.allclose(by_length["visual error max [cm]"], 100 * visual.max(1))
    assert np.allclose(by_length["odometry error mean [cm]"], np.round(100 * odometry.mean(1), 2))
    assert "odometry error max [cm]" in (tables / "routes_by_length.tex").read_text()


def test_error_figure_and_trajectories_show_the_trials() -> None:
    results = []
    for k, job in enumerate(_jobs()):
        record = _trial_record(job, k)
        poses = [record[name] for name in ("outbound", "homing", "intermediate", "odometry")]
        trial, length = job.trial.name, job.trial.length
        results.append(RouteResult("klt-sector", *poses, trial=trial, planned_length_m=length))
    assert [r.final_error_m for r in results] == pytest.approx([v for v, _ in ERRORS.values()])
    styles = method_styles(["klt-sector"])
    with report_style():
        errors = route_error_figure(results, styles)
        straight = route_figure(results[:3], styles)
    lines = {line.get_label(): line for line in errors.axes[0].get_lines()}
    visual = np.array(list(ERRORS.values()))[:, 0].reshape(2, 3)
    assert np.allclose(lines["klt-sector"].get_xdata(), [1.0, 3.0])  # the mean per length
    assert np.allclose(lines["klt-sector"].get_ydata(), visual.mean(axis=1))
    assert errors.axes[0].get_yscale() == "log"
    # a straight 1 m route still fills its panel: equal scales, x widened to the panel's shape
    ax = straight.axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    box = ax.get_position()
    shape = box.width * straight.get_figwidth() / (box.height * straight.get_figheight())
    assert ax.get_aspect() == 1.0
    assert (x1 - x0) / (y1 - y0) == pytest.approx(shape, rel=0.15)
    assert "line-1m-r0" in ax.get_title()
    plt.close(errors)
    plt.close(straight)


def test_missing_corrupt_and_stale_trials_get_a_warning_page(route_run: Path) -> None:
    (route_run / "routes" / "line-1m-r1.json").unlink()
    (route_run / "routes" / "line-3m-r0.json").write_text('{"key": "abc')
    stale = route_run / "routes" / "line-3m-r1.json"
    record = json.loads(stale.read_text())
    stale.write_text(json.dumps({**record, "key": "0123456789abcdef"}))
    broken = route_run / "routes" / "line-3m-r2.json"
    record = json.loads(broken.read_text())
    del record["summary"]["odometry_error_m"]
    broken.write_text(json.dumps(record))

    outcome = write_report(route_run)
    key = {job.trial.name: job.key for job in _jobs()}["line-3m-r1"]
    assert outcome.warnings[0] == "routes/line-1m-r1.json (trial line-1m-r1: missing)"
    assert outcome.warnings[1].startswith("routes/line-3m-r0.json (trial line-3m-r0: corrupt, ")
    assert outcome.warnings[2] == (
        "routes/line-3m-r1.json (trial line-3m-r1: of another configuration, key "
        f"0123456789abcdef != {key})"
    )
    assert outcome.warnings[3] == (
        "routes/line-3m-r2.json (trial line-3m-r2: corrupt, summary.odometry_error_m: Field "
        "required)"
    )
    assert len(outcome.warnings) == 4
    pdf = route_run / "report" / "report.pdf"
    assert "missing or corrupt trial files: 4 (see the next page)" in _text(pdf, 0)
    warning = _text(pdf, 1)
    assert "Warning: missing job results" in warning
    for name in ("line-1m-r1", "line-3m-r0", "line-3m-r1", "line-3m-r2"):
        assert f"routes/{name}.json" in warning
    # one trajectory page fewer (the 3 m trials are all gone), one warning page more
    assert len(pypdf.PdfReader(pdf).pages) == PAGES
    trials = pd.read_csv(route_run / "report" / "tables" / "routes.csv")
    assert list(trials["trial"]) == ["line-1m-r0", "line-1m-r2"]


def test_bad_route_runs_are_data_errors(route_run: Path) -> None:
    config = json.loads((route_run / "config.resolved.json").read_text())
    config["routes"][0]["waypoints"] = [[1.0, 1.0]]
    (route_run / "config.resolved.json").write_text(json.dumps(config))
    with pytest.raises(DataError, match=r"config\.resolved\.json: routes\.0\.waypoints"):
        write_report(route_run)
    config["routes"][0]["waypoints"] = [list(HOME), [1.7, 4.8]]
    (route_run / "config.resolved.json").write_text(json.dumps(config))
    for path in (route_run / "routes").glob("*.json"):
        path.unlink()
    with pytest.raises(DataError, match=r"no trial results to report on \(missing: routes/"):
        write_report(route_run)


@pytest.mark.slow  # CI time: test_report checks a grid report's bytes
def test_two_route_reports_are_byte_identical(route_run: Path, tmp_path: Path) -> None:
    first = write_report(route_run, ["pdf", "html", "md"], tmp_path / "a").files
    second = write_report(route_run, ["pdf", "html", "md"], tmp_path / "b").files
    assert [p.relative_to(tmp_path / "a") for p in first] == [
        p.relative_to(tmp_path / "b") for p in second
    ]
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name


def test_cli_report_of_a_route_run(route_run: Path) -> None:
    (route_run / "routes" / "line-3m-r2.json").unlink()
    result = CliRunner().invoke(main, ["report", str(route_run), "--format", "md"])
    assert result.exit_code == 0, result.output
    printed = [Path(line) for line in result.stdout.splitlines()]
    assert route_run / "report" / "report.md" in printed and all(p.is_file() for p in printed)
    assert "routes/line-3m-r2.json (trial line-3m-r2: missing)" in result.stderr


def test_a_run_of_several_methods_compares_them_on_the_same_trials(tmp_path: Path) -> None:
    """klt-sector as in the other tests, warping 1 cm farther from home on every trial: the
    per-method table, the paired test (6 trials, all one way: exact sign-flip p = 2 / 2**6),
    per length, the figures with intervals and one trajectory page per route length."""
    run = tmp_path / "run"
    config = _config(run).model_copy(
        update={
            "methods": [MethodEntry(method="klt-sector"), MethodEntry(method="warping")],
            "success_radius_m": 0.02,
        }
    )
    (run / "routes").mkdir(parents=True)
    (run / "config.resolved.json").write_text(json.dumps(config.model_dump(mode="json")))
    environment = {"config_file": "tiny.yaml", "started": STARTED, "versions": {}}
    (run / "environment.json").write_text(json.dumps(environment))
    for k, trial in enumerate(plan_trials(config)):
        for label, shift in (("klt-sector", 0.0), ("warping", 0.01)):
            job = RouteJob(config, trial, label)
            record = _trial_record(job, k)
            record["homing"][-1][0] += shift
            record["summary"] |= {
                "visual_error_m": record["summary"]["visual_error_m"] + shift,
                "visual_path_m": 2.0 * trial.length,
                "legs": 2,
            }
            job.result_path(run).parent.mkdir(exist_ok=True)
            job.result_path(run).write_text(json.dumps(record))
    outcome = write_report(run, ["md"])
    assert outcome.warnings == []
    tables = run / "report" / "tables"
    visual = np.array(list(ERRORS.values()))[:, 0]
    odometry = np.array(list(ERRORS.values()))[:, 1]
    by_method = pd.read_csv(tables / "routes_by_method.csv")
    assert list(by_method["method"]) == ["klt-sector", "warping", "odometry"]
    assert np.allclose(
        by_method["final error mean [cm]"],
        np.round(100 * np.array([visual.mean(), visual.mean() + 0.01, odometry.mean()]), 2),
    )
    # within 2 cm: klt-sector 5 trials, warping the 4 below 1 cm, odometry none
    assert np.allclose(by_method["success [%]"], np.round([500 / 6, 400 / 6, 0]))
    assert list(by_method["path / route length"][:2]) == [2.0, 2.0]
    paired = pd.read_csv(tables / "routes_paired.csv").set_index(["A", "B"])
    row = paired.loc[("klt-sector", "warping")]
    assert row["trials"] == 6 and row["B - A final error [cm]"] == pytest.approx(1.0)
    assert row["p sign-flip"] == pytest.approx(2 / 64, abs=1e-3)
    assert (row["success A only"], row["success B only"]) == (1, 0)
    assert row["p McNemar"] == pytest.approx(1.0)
    assert paired.loc[("odometry", "klt-sector"), "B - A final error [cm]"] < 0
    by_length = pd.read_csv(tables / "routes_by_method_length.csv")
    assert len(by_length) == 3 * 2 and list(by_length["trials"]) == [3] * 6
    trials = pd.read_csv(tables / "routes.csv")
    assert list(trials["method"][:2]) == ["klt-sector", "warping"] and len(trials) == 12
    # Seed 000's findings are klt-sector's: the other method's trials stay out of them.
    from homebench.report.across_runs.findings import _route_tables

    assert list(_route_tables([run])[0]["method"]) == ["klt-sector"] * 6
    figures = sorted(p.name for p in (run / "report" / "figures").glob("*.png"))
    assert figures == [
        "final_error.png",
        "final_error_intervals.png",
        "trajectories_line-1m-r0.png",
        "trajectories_line-3m-r0.png",
    ]
