"""What `homebench run` prints at the end of a route or closed-loop run: a summary as compact
as the grid headline (the columns a reader needs, ``--`` for a missing value, empty columns
left out), and a note when a route run's odometry is perfect."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from click.testing import CliRunner

from homebench.cli import main
from homebench.experiments.robot import DriftModel
from homebench.experiments.route.experiment import odometry_notes
from homebench.report.consoles import closed_loop_console, route_console
from homebench.report.tables import CONSOLE_WIDTH, MISSING_TEXT

#: Methods of typical name lengths.
LABELS = ["klt-sector", "warping", "fourier-warping"]


def _route_jobs(catchment: bool = False) -> pd.DataFrame:
    """Two trials homed by each of LABELS, the columns of a route run's routes.csv: the
    klt-sector columns None for the pairwise methods, as the trial records write them."""
    rows = []
    for k, label in enumerate(LABELS):
        for trial, length in (("tour-2m", 2.0), ("tour-4m", 4.0)):
            klt = label == "klt-sector"
            rows.append({
                "trial": trial, "method": label, "route": "tour", "length_m": length,
                "driven_m": length, "frames": 40, "features": 120 if klt else None,
                "features_home": 80 if klt else None, "min_shared": 40 if klt else None,
                "snapshots": None if klt else 4, "n_intermediate": 3,
                "visual_status": "reached", "visual_steps": 50 + k,
                "visual_error_m": 0.01 * (k + 1),
                "visual_heading_error_deg": 1.0, "visual_path_m": 1.2 * length, "legs": 4,
                "odometry_error_m": 0.2, "odometry_heading_error_deg": 3.0,
                "odometry_drift_at_end_m": 0.1,
                "probe_error_on_route_deg": 5.0 if catchment and k == 2 else None,
                "catchment_m": 0.5 if catchment and k == 2 else None,
                "success": k < 2,
            })  # fmt: skip
    return pd.DataFrame(rows)


def _closed_loop_summary(collisions: int = 0) -> pd.DataFrame:
    """A closed-loop summary.csv: two styles, LABELS and the controls; no catchment (starts
    given as points)."""
    rows = []
    for style in ("posters", "lab"):
        for k, method in enumerate([*LABELS, "truth", "random"]):
            rows.append({
                "style": style, "method": method, "trials": 24, "goals": 1,
                "success": 1.0 - 0.1 * k, "success_lo": 0.8 - 0.1 * k, "success_hi": 1.0,
                "final_distance_m": 0.1 + 0.01 * k, "path_ratio": 1.2 if k < 4 else math.nan,
                "steps": 30.0 + k, "no_estimate_share": 0.01 * k,
                "collisions": collisions if k == 1 else 0, "outside": 0,
                "s_per_step": 0.0123, "catchment_m2": math.nan,
            })  # fmt: skip
    return pd.DataFrame(rows)


def _fits(text: str) -> None:
    """Every line within the console's width, no raw missing value."""
    for line in text.splitlines():
        assert len(line) <= CONSOLE_WIDTH, line
        for raw in ("None", "nan", "NaN"):
            assert raw not in line.split(), line


def test_the_route_summary_is_one_row_per_method_with_odometry_last() -> None:
    text = route_console(_route_jobs(), LABELS, 0.1)
    _fits(text)
    header = next(line for line in text.splitlines() if line.startswith("method"))
    assert header.split("  ")[0] == "method"
    for column in ("success [%]", "error [cm]", "median"):
        assert column in header
    rows = [line.split()[0] for line in text.splitlines()[2:] if line.split()
            and line.split()[0] in [*LABELS, "odometry"]]  # fmt: skip
    assert rows == [*LABELS, "odometry"]
    assert "features" not in text and "catchment" not in text  # empty here: left out
    odometry = next(line for line in text.splitlines() if line.startswith("odometry"))
    assert MISSING_TEXT in odometry.split()  # no homing path of its own


def test_the_route_summary_shows_the_catchment_where_a_method_has_one() -> None:
    text = route_console(_route_jobs(catchment=True), LABELS, 0.1)
    _fits(text)
    assert "catchment [m]" in text
    cells = {line.split()[0]: line.split() for line in text.splitlines() if line.split()}
    assert cells["fourier-warping"][-1] == "0.50"
    assert cells["warping"][-1] == MISSING_TEXT


def test_the_closed_loop_summary_leaves_out_empty_and_all_zero_columns() -> None:
    text = closed_loop_console(_closed_loop_summary())
    _fits(text)
    header = next(line for line in text.splitlines() if line.strip().startswith("method"))
    assert "catchment" not in text and "collisions" not in text and "left" not in header
    assert "style posters" in text and "style lab" in text  # as the grid headline's groups
    assert "success" in header and "path ratio" in header
    shown = closed_loop_console(_closed_loop_summary(collisions=3))
    _fits(shown)
    assert "collisions" in shown


def test_perfect_odometry_gets_a_note_and_drift_none() -> None:
    (note,) = odometry_notes(DriftModel())
    assert "odometry" in note and "perfect" in note and "drift" in note
    assert odometry_notes(DriftModel(heading_bias=0.01)) == ()


def test_a_route_run_without_drift_prints_the_compact_summary_and_the_note_once(
    tmp_path: Path,
) -> None:
    """A 0.6 m route homed by warping in a tiny world (about 3 s)."""
    config = {
        "kind": "route",
        "name": "tiny-route",
        "output": str(tmp_path / "run"),
        "world": {"seed": 0, "grid": {"shape": [5, 5], "spacing": 0.3},
                  "unfolded": {"width": 48},
                  "raw": {"width": 32, "height": 32, "inner_radius": 2.0, "outer_radius": 15.0}},
        "routes": [{"name": "ell", "waypoints": [[2.0, 2.5], [2.0, 3.1]]}],
        "motion": {"step_length": 0.1, "max_turn_deg": 30},
        "methods": [{"method": "warping"}],
    }  # fmt: skip
    path = tmp_path / "route.yaml"
    path.write_text(yaml.safe_dump(config))
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress", "--no-report"])
    assert result.exit_code == 0, result.output
    _fits("\n".join(line for line in result.stdout.splitlines() if str(tmp_path) not in line))
    assert "odometry_error_m" not in result.stdout  # the routes table's columns stay in it
    notes = [line for line in result.stderr.splitlines() if "perfect" in line]
    assert len(notes) == 1 and notes[0].startswith("homebench: note: "), result.stderr
    table = pd.read_csv(tmp_path / "run" / "tables" / "routes.csv")
    assert "odometry_error_m" in table.columns and np.all(table["odometry_error_m"] == 0)
