"""``homebench compare``: how runs differ per condition and method (AE, AHC, RR, time).

The first run is the reference. Each (condition, method) gets one row per run: its values,
their differences to the reference's (the reference's own rows: 0) and its time ratios
(run / reference; the reference's: 1). Every number is rebuilt from the job files.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from homebench.errors import DataError
from homebench.report.run_data import load_run
from homebench.report.tables import FIXED2, FIXED3, TableView, make_view

#: Compared summary columns: source -> (value header, difference header, digits).
DIFFERENCES = {
    "mean_ae_deg": ("mean AE [deg]", "mean AE diff [deg]", FIXED2),
    "ahc": ("AHC", "AHC diff", FIXED3),
    "rr": ("RR", "RR diff", FIXED3),
}
#: Time columns compared as ratios: source -> header.
RATIOS = {
    "describe_ms": "describe time ratio",
    "home_ms": "home time ratio",
}
KEYS = ["condition", "method"]


@dataclass(frozen=True)
class Comparison:
    table: pd.DataFrame  # numeric, one row per (condition, method, run)
    warnings: list[str]  # missing jobs, and (condition, method) absent from a run

    def view(self) -> TableView:
        """The table rounded for printing and writing (CSV, MD, TeX)."""
        digits = {header: rule for header, _, rule in DIFFERENCES.values()}
        digits |= {diff: rule for _, diff, rule in DIFFERENCES.values()}
        digits |= dict.fromkeys(RATIOS.values(), FIXED2)
        title = f"Runs compared with {self.table['run'].iloc[0]} (diff = run - reference)"
        return make_view("comparison", title, self.table, digits)


def _records(summary: pd.DataFrame) -> dict[tuple[str, str], dict[str, float]]:
    return {(r["condition"], r["method"]): r for r in summary.to_dict("records")}


def compare_runs(run_dirs: Sequence[Path]) -> Comparison:
    """Compare runs (at least two) with the first; DataError for a folder that is no run."""
    if len(run_dirs) < 2:
        raise DataError("compare needs at least two run folders")
    names = [str(d) for d in run_dirs]
    runs = [load_run(Path(d)) for d in run_dirs]
    warnings = [f"{name}: missing {job}" for name, run in zip(names, runs, strict=True)
                for job in run.tables.missing_jobs]  # fmt: skip
    for name, run in zip(names, runs, strict=True):
        if run.tables.summary.empty:
            raise DataError(f"{name}: no job results to compare")
    records = [_records(run.tables.summary) for run in runs]
    rows = []
    for key in sorted(set().union(*records)):
        base = records[0].get(key, {})
        for name, found in zip(names, records, strict=True):
            if key not in found:
                warnings.append(f"{name}: no results for {key[1]} under {key[0]}")
            rows.append(_row(name, key, found.get(key, {}), base))
    return Comparison(pd.DataFrame(rows), warnings)


def _row(
    name: str, key: tuple[str, str], mine: dict[str, float], base: dict[str, float]
) -> dict[str, object]:
    """One run's values for ``key`` (condition, method) against the reference's ``base``."""
    nan = float("nan")
    row: dict[str, object] = {"condition": key[0], "method": key[1], "run": name}
    for column, (header, diff, _) in DIFFERENCES.items():
        row[header] = mine.get(column, nan)
        row[diff] = mine.get(column, nan) - base.get(column, nan)
    for column, header in RATIOS.items():
        denominator = base.get(column, nan)
        row[header] = mine.get(column, nan) / denominator if denominator > 0 else nan
    return row
