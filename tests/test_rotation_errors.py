"""Rotation estimates are a metric of their own: the true heading change per pair, each
method's rotation error, and the summary's mean rotation error with its interval."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from conftest import arena_config, run_config


def test_rotation_truth_and_errors_on_rotated_current_views(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """Every arena image is taken at one heading, so the true heading change of a pair is the
    rotation applied to its current view; the visual compass finds it to within a few
    columns (1.25 deg each) near the goal, and a method without rotations has none."""
    config = arena_config(
        tmp_path,
        arena_manifest,
        rotate_current={"enabled": True, "seed": 3},
        methods=[{"method": "visual-compass"}, {"method": "alv"}],
    )
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    tables = tmp_path / "run" / "tables"
    pairs = pd.read_csv(tables / "pairs.csv")  # 6 significant digits: tolerances of 1e-5
    assert (pairs["rotation_rad"] != 0).any()
    turn = np.exp(1j * (pairs["rotation_truth_rad"] - pairs["rotation_rad"]))
    np.testing.assert_allclose(np.angle(turn), 0.0, atol=1e-5)  # equal up to whole turns
    compass = pairs[pairs["method"] == "visual-compass"]
    expected = np.abs(np.angle(np.exp(1j * (compass["rotation_estimate_rad"] -
                                            compass["rotation_truth_rad"]))))  # fmt: skip
    np.testing.assert_allclose(compass["rotation_error_rad"], expected, atol=1e-5)
    np.testing.assert_allclose(
        compass["rotation_error_deg"], np.degrees(compass["rotation_error_rad"]), rtol=1e-5
    )
    near = compass[compass["distance_m"] < 0.35]
    assert near["rotation_error_deg"].max() < 5.0
    assert pairs.loc[pairs["method"] == "alv", "rotation_error_rad"].isna().all()

    summary = pd.read_csv(tables / "summary.csv").set_index("method")
    row = summary.loc["visual-compass"]
    assert abs(row["rotation_error_deg"] - np.mean(compass["rotation_error_deg"])) < 1e-4
    assert row["rotation_error_deg_lo"] <= row["rotation_error_deg"] <= row["rotation_error_deg_hi"]
    assert np.isnan(summary.loc["alv", "rotation_error_deg"])
