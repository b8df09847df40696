"""The Brains on Board section of the documentation's databases page (the README's until it is
slimmed down), run as a user runs it (tests/console_blocks.py: every ``$`` line of its console
blocks a shell command in a process of its own, a ``$ cat FILE`` line a file the test writes, any
other line text the output must hold), on folders written the way BoB's tools write them
(tests/bob_folders.py: a grid labelled as BoB's grid recorder labels it, a route whose camera
faced the way it travelled, laid out by BoB's renderer's formula) in place of
``~/data/ant_grid`` and ``~/data/ant_route``."""

from __future__ import annotations

from pathlib import Path

import pytest
from bob_folders import bend_points, write_recorder_grid, write_route
from console_blocks import Step, console_steps, run_steps, section, user_env

PAGE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "databases.md"
SECTION = ("## Brains on Board image databases", "## Manifest schema")


def section_steps() -> list[Step]:
    """The steps of every console block of the page's Brains on Board section."""
    return console_steps(section(PAGE.read_text(), *SECTION))


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("readme-bob")
    return {
        "~/data/ant_grid": write_recorder_grid(root / "ant_grid", (5, 4)),
        "~/data/ant_route": write_route(root / "ant_route", bend_points()),
    }


def test_the_section_has_the_commands_it_documents() -> None:
    commands = [step.command.split(" #")[0] for step in section_steps()]
    for verb in ("data verify", "data show", "data check", "run"):
        assert any(f"homebench {verb} " in c for c in commands), verb


# CI time: docs/tutorials/own-bob.md runs the same commands on a BoB grid and route in processes
# (verify, data check exit 3, homebench.yaml, check again, the route's headings, both runs);
# data check proposing bob-recorder order: test_grid_order, test_bob_holes
@pytest.mark.slow
def test_every_command_of_the_bob_section_runs_as_shown(
    folders: dict[str, Path], tmp_path: Path
) -> None:
    run_steps(section_steps(), tmp_path, user_env(), lambda text: _located(text, folders))


def _located(text: str, folders: dict[str, Path]) -> str:
    """``text`` with the page's folders replaced by the test's."""
    for name, folder in folders.items():
        text = text.replace(name, str(folder))
    return text
