"""Threshold checks of a run's summary (the CI smoke benchmark): one reason per failure."""

from __future__ import annotations

import math

import pandas as pd

from homebench.config import Check

#: (config field, summary column, "min" or "max", unit shown in the reason)
_RULES = (
    ("ahc_min", "ahc", "min", ""),
    ("rr_min", "rr", "min", ""),
    ("mean_ae_max_deg", "mean_ae_deg", "max", " deg"),
    ("no_estimate_max", "no_estimate_share", "max", ""),
)


def failed_checks(summary: pd.DataFrame, checks: dict[str, Check]) -> list[str]:
    """Every threshold a method misses in some condition, as one line each.

    A method with no row in the summary (no results), or a metric that is NaN, fails its
    checks: a smoke benchmark must not pass by producing nothing.
    """
    reasons = []
    for label, check in sorted(checks.items()):
        rows = summary[summary["method"] == label] if not summary.empty else summary
        if check.conditions is not None and not rows.empty:
            rows = rows[rows["condition"].isin(check.conditions)]
        if rows.empty:
            reasons.append(f"{label}: no results to check")
            continue
        for field, column, kind, unit in _RULES:
            limit = getattr(check, field)
            if limit is None:
                continue
            for _, row in rows.iterrows():
                value = float(row[column])
                ok = not math.isnan(value) and (value >= limit if kind == "min" else value <= limit)
                if not ok:
                    sign = ">=" if kind == "min" else "<="
                    reasons.append(
                        f"{label} in {row['condition']}: {column} = {value:.3g}{unit}, "
                        f"needs {sign} {limit:g}{unit}"
                    )
    return reasons
