"""homebench.api: a config run from Python gives the command line's tables; tables as frames;
one report figure by its file stem."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pytest
import yaml
from click.testing import CliRunner
from conftest import arena_config
from matplotlib.figure import Figure

from homebench import api
from homebench.cli import main
from homebench.errors import ConfigError, DataError


@pytest.fixture(scope="module")
def api_run(tmp_path_factory: pytest.TempPathFactory, arena_manifest: Path) -> Path:
    """The arena config (two goals, two warping entries) run through the API into its own
    folder, with one override."""
    folder = tmp_path_factory.mktemp("api")
    config = folder / "config.yaml"
    config.write_text(yaml.safe_dump(arena_config(folder, arena_manifest)))
    return api.run(config, ["goals=[[1, 2]]"], jobs=1, run_dir=folder / "api run", progress=False)


def test_run_returns_the_run_folder_named_by_run_dir(api_run: Path) -> None:
    assert api_run.name == "api run"
    assert (api_run / "tables" / "summary.csv").is_file()
    assert not (api_run / "report").exists()  # no report unless asked for


def test_the_api_and_the_command_line_write_the_same_tables(
    api_run: Path, tmp_path: Path, arena_manifest: Path
) -> None:
    config = tmp_path / "config.yaml"
    config.write_text(yaml.safe_dump(arena_config(tmp_path, arena_manifest)))
    result = CliRunner().invoke(
        main, ["run", str(config), "goals=[[1, 2]]", "--no-progress", "--no-report"]
    )
    assert result.exit_code == 0, result.stderr
    for name in ("goals", "ahc", "rr_starts"):
        expected = (tmp_path / "run" / "tables" / f"{name}.csv").read_text()
        assert (api_run / "tables" / f"{name}.csv").read_text() == expected, name


def test_tables_are_frames_of_the_run(api_run: Path) -> None:
    t = api.tables(api_run)
    assert list(t.summary["method"]) == ["warping", "warping-coarse"]
    assert set(t.summary["condition"]) == {"arena-arena"}
    assert len(t.pairs) == 2 * 19  # two methods, every current of the 4 x 5 grid but the goal
    assert set(zip(t.goals["goal_i"], t.goals["goal_j"], strict=True)) == {(1, 2)}
    assert len(t.rr_starts) == 2 * 20 and t.missing_jobs == ()
    assert t.summary_by_seed.empty
    comparisons = t.comparisons
    assert set(comparisons["metric"]) == {"mean_ae_deg", "ahc", "rr"}
    assert set(zip(comparisons["method_a"], comparisons["method_b"], strict=True)) == {
        ("warping", "warping-coarse")
    }


def test_one_figure_by_its_stem_and_the_others_closed(api_run: Path) -> None:
    plt.close("all")
    names = api.figure_names(api_run)
    assert len(names) > 3 and len(set(names)) == len(names)
    assert plt.get_fignums() == []
    fig = api.figure(api_run, names[2])
    assert isinstance(fig, Figure) and fig.axes
    assert plt.get_fignums() == [fig.number]
    plt.close(fig)


def test_an_unknown_figure_names_the_closest(api_run: Path) -> None:
    last = api.figure_names(api_run)[-1]
    with pytest.raises(DataError, match=rf"unknown figure '{last}x' \(did you mean '{last}'\?\)"):
        api.figure(api_run, f"{last}x")


def test_tables_of_a_folder_that_is_no_run(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="no such run folder"):
        api.tables(tmp_path / "nothing")


def test_a_route_config_is_left_to_the_command_line(tmp_path: Path) -> None:
    config = tmp_path / "routes.yaml"
    config.write_text("kind: route\nname: r\n")
    with pytest.raises(ConfigError, match="a route config"):
        api.run(config)
