"""Seed 001's findings that hold in every world style (slow: about 15 minutes on 2 cores).

Run with ``pytest -m slow``. The reference run of ``configs/findings_sift.yaml`` (4 styles x 3
seeded worlds x 10 goals; ``reports/README.md``) tested each finding per style with goal-level
sign-flip tests, Holm-corrected within the style. Only the findings that held there in **every**
style are asserted here, at the same level (alpha = 0.05), on two worlds per style (20 goals):

- mismatch elimination lowers the AE under original-original (P below PN);
- P's AHC and W's AHC stay above 0 under original-original and original-arboreal.

The others depend on the place and are not asserted: P errs less than W only outdoors (the
opposite holds in the poster room, the lab and the corridor), the illumination change hurts W
more than P except (not significantly) in the lab, and W beats P at 360-390 cm in the lab and
the corridor but not outdoors. A finding that depends on the style is a result, not a failure.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from conftest import run_config

from homebench.analysis.findings import ALPHA
from homebench.report.across_runs.findings import findings_of_runs

CONFIG = Path(__file__).parent.parent / "configs" / "findings_sift.yaml"
ROBUST = [
    "P<PN AE original-original",
    "P AHC>0 original-original",
    "P AHC>0 original-arboreal",
    "W AHC>0 original-original",
    "W AHC>0 original-arboreal",
]


@pytest.mark.slow
def test_findings_that_hold_in_every_style(tmp_path: Path) -> None:
    data = yaml.safe_load(CONFIG.read_text())
    data.update(output=str(tmp_path / "run"), seeds=[0, 1])
    result = run_config(tmp_path, data)
    assert result.exit_code == 0, result.output
    found = findings_of_runs([tmp_path / "run"], alpha=ALPHA)
    table = found.table.set_index(["place", "finding"])
    for style in data["styles"]:
        for finding in ROBUST:
            row = table.loc[(style, finding)]
            assert row["verdict"] == "holds", (style, finding, row.to_dict())
