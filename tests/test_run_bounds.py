"""Nothing unbounded: every size and count a config sets is checked against what one run can
hold before any work, and refused with one line naming the key, exit 2, in bounded memory."""

from __future__ import annotations

import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from click.testing import CliRunner
from conftest import homebench_limited
from pydantic import ValidationError

from homebench.bounds import MAX_JOBS, MAX_PAIRS
from homebench.cli import main
from homebench.config import RunConfig, UnfoldConfig
from homebench.data.synth.spec import WorldSpec
from homebench.errors import ConfigError
from homebench.evaluation.plan import check_size
from homebench.experiments.closed_loop.config import ClosedLoopConfig
from homebench.experiments.closed_loop.starts import candidate_starts
from homebench.geometry import Grid
from homebench.image_header import MAX_IMAGE_PIXELS

CONFIGS = Path(__file__).resolve().parent.parent / "configs"
#: Values of a parameter swept 200 times: three such lists make 8,000,000 grid points.
SWEEP = "[" + ", ".join(str(4 + k) for k in range(200)) + "]"


@pytest.mark.parametrize(
    ("config", "override", "key"),
    [
        (
            "quickstart.yaml",
            "databases.original.world.unfolded.width=100000000",
            "databases.original.world.unfolded: ",
        ),
        (
            "quickstart.yaml",
            "databases.day.world.raw={width: 100000, height: 100000}",
            "databases.day.world.raw: ",
        ),
        ("quickstart.yaml", "unfold.width=100000000", "unfold: "),
        ("klt_route.yaml", "routes.0.repeats=1000000000", "routes[0].repeats: "),
        ("klt_route.yaml", "world.unfolded.width=100000000", "world.unfolded: "),
        ("closed_loop.yaml", "starts={random: 1000000000, seed: 0}", "starts.random: "),
        ("closed_loop.yaml", "starts={spacing: 0.0001}", "starts.spacing: "),
        ("quickstart.yaml", "goals={random: 1000000000000}", "goals.random: "),
        (
            "quickstart.yaml",
            f"methods.0.grid={{n_rho: {SWEEP}, n_alpha: {SWEEP}, n_psi: {SWEEP}}}",
            "methods[0].grid: ",
        ),
        ("quickstart.yaml", "metrics.ahc.bin_step_cm=0.000001", "metrics.ahc: "),
    ],
)
def test_a_size_or_count_beyond_what_a_run_holds_is_refused_at_once(
    tmp_path: Path, config: str, override: str, key: str
) -> None:
    """Each of these grew the main process to gigabytes (or ran a minute to a MemoryError)."""
    start = time.monotonic()
    done = homebench_limited(
        "run", str(CONFIGS / config), override, f"output={tmp_path / 'run'}", "--no-progress"
    )
    assert time.monotonic() - start < 30
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("homebench: error: "), done.stderr
    assert key in lines[0]
    assert not (tmp_path / "run").exists()


def test_the_image_limit_is_the_manifests_for_every_generated_image() -> None:
    side = int(MAX_IMAGE_PIXELS**0.5)
    WorldSpec(raw={"width": side, "height": side})  # at the limit: fine
    with pytest.raises(ValidationError, match=f"{MAX_IMAGE_PIXELS:,} pixels"):
        WorldSpec(raw={"width": side + 1, "height": side + 1})
    with pytest.raises(ValidationError, match=f"{MAX_IMAGE_PIXELS:,} pixels"):
        WorldSpec(unfolded={"width": 2 * side})
    with pytest.raises(ValidationError, match=f"{MAX_IMAGE_PIXELS:,} pixels"):
        UnfoldConfig(width=2 * side)


def test_the_bounds_leave_room_for_the_largest_experiments() -> None:
    """configs/findings_sift.yaml with every goal of the 10 x 17 grids: 4 styles x 3 worlds x
    3 conditions x 3 methods x 170 goals = 18,360 jobs of 169 pairs."""
    jobs = 4 * 3 * 3 * 3 * 170
    assert 50 * jobs <= MAX_JOBS and jobs * 169 <= MAX_PAIRS


def test_every_goal_of_a_large_grid_is_refused_before_planning() -> None:
    """goals: all counts the grid's positions when the run starts: 1,000 x 1,000 positions make
    a million jobs of 999,999 pairs each."""
    config = RunConfig(
        output="run",
        databases={"big": "big"},
        conditions=["big-big"],
        goals="all",
        methods=[{"method": "warping"}],
    )
    sources = {("big", (None, None)): SimpleNamespace(grid=Grid((1000, 1000), 0.3, (0.0, 0.0)))}
    start = time.monotonic()
    with pytest.raises(ConfigError, match=r"^c\.yaml: goals: 1,000,000: 999,999,000,000 pairs"):
        check_size(config, sources, "c.yaml")
    assert time.monotonic() - start < 10


def test_lattice_starts_on_a_database_are_counted_when_its_grid_is_known() -> None:
    config = ClosedLoopConfig(
        kind="closed-loop",
        output="run",
        database="synth-original",
        goals=[{"grid": [1, 1]}],
        starts={"spacing": 0.0001},
    )
    assert config.count_problem() == ""  # no region, no world: nothing to count yet
    with pytest.raises(ConfigError, match=r"^starts\.spacing: 1,296,075,001 x 2 \(methods\): "):
        candidate_starts(config, (0.0, 0.0, 2.7, 4.8))


def test_data_generate_takes_the_jobs_run_takes(tmp_path: Path) -> None:
    for command in (["data", "generate", "synth-original"], ["run", str(CONFIGS / "smoke.yaml")]):
        result = CliRunner().invoke(main, [*command, "--jobs", "-5"])
        assert result.exit_code == 2, result.output
        message = "jobs must be a positive number, or -1 for all cores (got -5)"
        assert result.stderr == f"homebench: error: {message}\n"
