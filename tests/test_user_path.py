"""The path of a researcher with recordings of their own: a database in Vardy's layout with a
hand-written manifest in their conventions (clockwise panoramas, azimuth 0 at column 100,
heading 90 deg; tests/vardy_layout.py), and every documented command over it, each run as the
user runs it: a subprocess of ``python -m homebench``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from vardy_layout import write_database

VARIANTS = ("original", "arboreal", "day")

#: Seed 001's experiment on the user's sets: P, PN and W as the paper names them, min-warping.
CONFIG = """\
name: our-room
output: {output}
jobs: 2
databases:
  original: {root}/original/manifest.yaml
  arboreal: {root}/arboreal/manifest.yaml
  day: {root}/day/manifest.yaml
conditions: [original-original, original-arboreal, original-day]
goals: [[2, 3], [1, 5]]
currents: all
methods:
  - {{method: sift-unfolded, label: P}}
  - method: sift-unfolded
    label: PN
    params: {{horizon_constraint: false, half_plane_constraint: false}}
  - {{method: warping, label: W}}
  - {{method: min-warping}}
"""


@pytest.fixture(scope="module")
def databases(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("our-room")
    for variant in VARIANTS:
        write_database(root / variant, variant)
    return root


def homebench(*args: object, cwd: Path) -> subprocess.CompletedProcess[str]:
    """``python -m homebench ARGS`` in ``cwd``, as a user types it."""
    return subprocess.run(
        [sys.executable, "-m", "homebench", *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
        env=os.environ.copy(),
        timeout=600,
    )


def ok(result: subprocess.CompletedProcess[str]) -> str:
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


# CI time: docs/tutorials/own-grid.md runs a hand-written Vardy-layout manifest through data
# verify, a data check that catches its mirrored direction, the fix and a run, each in a process;
# seed-001.md runs P, PN and W and findings; tour.md runs report and compare
@pytest.mark.slow
def test_every_command_on_a_hand_written_database(databases: Path, tmp_path: Path) -> None:
    manifest = databases / "original" / "manifest.yaml"
    verified = ok(homebench("data", "verify", manifest, cwd=tmp_path))
    assert f"our-room-original ({manifest}): 35 images OK" in verified
    ok(homebench("data", "show", manifest, "--out", tmp_path / "sheet", cwd=tmp_path))
    assert len(list((tmp_path / "sheet").glob("*.png"))) == 1
    assert "our-room-original (" in ok(homebench("data", "check", manifest, cwd=tmp_path))
    wrong = manifest.with_name("ccw.yaml")
    wrong.write_text(manifest.read_text().replace("direction: cw", "direction: ccw"))
    checked = homebench("data", "check", wrong, cwd=tmp_path)
    assert checked.returncode == 3, checked.stdout + checked.stderr
    assert "set images.unfolded.panorama.direction: cw (manifest: ccw)" in checked.stdout

    config = tmp_path / "our-room.yaml"
    config.write_text(CONFIG.format(output=tmp_path / "runs" / "our-room", root=databases))
    run = tmp_path / "runs" / "our-room"
    ok(homebench("run", config, "--no-progress", "--no-report", cwd=tmp_path))
    summary = pd.read_csv(run / "tables" / "summary.csv").set_index(["condition", "method"])
    # the images' conventions are read right: homing errs as little as on generated sets
    # (quick start, 5 x 7: min-warping 1.2 deg, warping 4.2 deg); a mirrored or turned
    # reading errs by tens of degrees
    assert summary.loc[("original-original", "min-warping"), "mean_ae_deg"] < 5.0
    assert summary.loc[("original-original", "W"), "mean_ae_deg"] < 15.0
    written = ok(homebench("report", run, "--format", "md", cwd=tmp_path))  # the PDF: elsewhere
    assert run / "report" / "report.md" in {Path(line) for line in written.splitlines()}
    # the report names the databases as the data commands do
    assert f"current: our-room-original ({manifest})" in (run / "report" / "report.md").read_text()
    findings = ok(homebench("findings", run, cwd=tmp_path))
    assert "| our-room | P errs less than W under original-day" in findings

    coarse = tmp_path / "runs" / "coarse"
    ok(homebench("run", config, "methods.2.params.n_rho=10", f"output={coarse}",
                 "--no-progress", "--no-report", cwd=tmp_path))  # fmt: skip
    board = ok(homebench("leaderboard", run, coarse, cwd=tmp_path))
    assert "original-day" in board and " @ " not in board  # the same databases: one column each
    board = ok(homebench("leaderboard", run, coarse, "--metric", "ahc_missing90", cwd=tmp_path))
    assert "AHC (no estimate = 90 deg)" in board
    compared = ok(homebench("compare", run, coarse, cwd=tmp_path))
    assert "config methods[2].params.n_rho: 20 -> 10" in compared
    assert "| paired" in compared and "unpaired" not in compared
