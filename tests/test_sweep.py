"""Sweeps in one config: every pair of databases, several world seeds, parameter grids."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from conftest import run_config

WORLD = {"grid": {"shape": [3, 3]}, "unfolded": {"width": 180}}


def test_sweep_keeps_every_factor_as_a_column(tmp_path: Path) -> None:
    config = {
        "output": str(tmp_path / "run"),
        "databases": {
            "original": {"world": {**WORLD, "variant": "original"}},
            "day": {"world": {**WORLD, "variant": "day"}},
        },
        "conditions": "all",
        "seeds": [0, 3],
        "goals": [[1, 1]],
        "methods": [
            {
                "method": "warping",
                "grid": {"n_rho": [5, 10], "n_columns": [36]},
                "params": {"n_psi": 36, "n_alpha": 36},
            }
        ],  # fmt: skip
    }
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    tables = tmp_path / "run" / "tables"
    pairs = pd.read_csv(tables / "pairs.csv")
    assert set(pairs["seed"]) == {0, 3}
    assert set(pairs["condition"]) == {
        "original-original",
        "original-day",
        "day-original",
        "day-day",
    }
    assert set(pairs["method"]) == {
        "warping[n_columns=36,n_rho=5]",
        "warping[n_columns=36,n_rho=10]",
    }
    assert set(pairs["param.n_rho"]) == {5, 10}
    assert (pairs["param.n_psi"] == 36).all()
    cross = pairs[pairs["condition"] == "day-original"]
    assert set(cross["current_database"]) == {"day"} and set(cross["goal_database"]) == {"original"}
    assert len(pairs) == 2 * 4 * 2 * 8  # seeds x conditions x grid points x currents
    by_seed = pd.read_csv(tables / "summary_by_seed.csv")
    assert len(by_seed) == 2 * 4 * 2
    goals = pd.read_csv(tables / "goals.csv")
    assert len(goals) == 2 * 4 * 2 and set(goals["seed"]) == {0, 3}
    # the two seeds are different rooms: their estimates differ somewhere
    a, b = (pairs[pairs["seed"] == s]["estimate_rad"].to_numpy() for s in (0, 3))
    assert (abs(a - b) > 1e-9).any()


@pytest.mark.slow  # CI time: test_sweep_keeps_every_factor_as_a_column runs a sweep
def test_styles_sweep_every_generated_database(tmp_path: Path) -> None:
    """``styles`` x ``seeds``: each generated database in every style and seed; the style is a
    column, the headline summary is per style, the goals table and RR starts carry it."""
    config = {
        "output": str(tmp_path / "run"),
        "databases": {
            "original": {"world": {**WORLD, "variant": "original"}},
            "day": {"world": {**WORLD, "variant": "day"}},
        },
        "conditions": ["original-day"],
        "styles": ["lab", "corridor"],
        "seeds": [0, 1],
        "goals": [[1, 1]],
        "methods": [{"method": "warping", "params": {"n_psi": 36, "n_alpha": 36}}],
    }
    result = run_config(tmp_path, config, "--no-report")
    assert result.exit_code == 0, result.output
    tables = tmp_path / "run" / "tables"
    pairs = pd.read_csv(tables / "pairs.csv")
    assert set(zip(pairs["style"], pairs["seed"], strict=True)) == {
        (style, seed) for style in ("lab", "corridor") for seed in (0, 1)
    }
    assert len(pairs) == 2 * 2 * 8
    summary = pd.read_csv(tables / "summary.csv")
    assert list(summary["style"]) == ["corridor", "lab"] and (summary["n_goals"] == 2).all()
    by_seed = pd.read_csv(tables / "summary_by_seed.csv")
    assert len(by_seed) == 4 and set(by_seed.columns) >= {"style", "seed"}
    assert set(pd.read_csv(tables / "rr_starts.csv")["style"]) == {"lab", "corridor"}
    # a lab and a corridor are different places: the estimates differ
    a, b = (pairs[pairs["style"] == s]["estimate_rad"].to_numpy() for s in ("lab", "corridor"))
    assert (abs(a - b) > 1e-9).any()
