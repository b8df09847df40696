"""Seed 001's findings on the generated worlds (slow: the full experiment, about a minute).

Run with ``pytest -m slow``. Measured on the reference machine (AHC / mean RR over the five
goals): original-original P 0.973 / 0.996, PN 0.965 / 0.995, W 0.935 / 0.913; original-day
P 0.948 / 0.969, W -0.067 / 0.024.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml
from conftest import run_config

CONFIG = Path(__file__).parent.parent / "configs" / "sift_paper.yaml"


@pytest.mark.slow
def test_sift_paper_findings_reproduce(tmp_path: Path) -> None:
    data = yaml.safe_load(CONFIG.read_text())
    data["output"] = str(tmp_path / "run")
    result = run_config(tmp_path, data)
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv")
    table = summary.set_index(["condition", "method"])
    for condition in ("original-original", "original-arboreal", "original-day"):
        p, pn, w = (table.loc[(condition, m)] for m in ("P", "PN", "W"))
        assert p["ahc"] > w["ahc"] and p["rr"] > w["rr"], condition  # P beats W
        assert p["rr"] >= pn["rr"] and p["ahc"] > pn["ahc"], condition  # elimination helps
    drop = table.loc["original-original"] - table.loc["original-day"]
    assert drop.loc["W", "ahc"] > 0.5 and drop.loc["W", "rr"] > 0.5  # warping collapses
    assert drop.loc["P", "ahc"] < 0.1 and drop.loc["P", "rr"] < 0.1  # P drops only slightly
