"""The README's Brains on Board section, run as a user runs it: every ``$`` line of its console
blocks is a shell command run in a process of its own, on folders written the way BoB's tools
write them (tests/bob_folders.py: a grid labelled as BoB's grid recorder labels it, a route
whose camera faced the way it travelled, laid out by BoB's renderer's formula) in place of
``~/data/ant_grid`` and ``~/data/ant_route``. A ``$ cat FILE`` line is followed by the file's
text, which the test writes; any other line under a command is text its output must hold;
``# exit N`` in a command's comment is its exit code (0 otherwise)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from bob_folders import bend_points, write_recorder_grid, write_route

README = Path(__file__).resolve().parents[1] / "README.md"
SECTION = ("### Brains on Board image databases", "### Manifest schema")


@dataclass
class Step:
    """A ``$`` line: its ``command``, the exit code it expects, the output lines it shows, or
    the file it shows (``cat``) and that file's lines."""

    command: str
    exit_code: int = 0
    shows: list[str] = field(default_factory=list)
    writes: str | None = None


def section_steps() -> list[Step]:
    """The steps of every console block of the README's Brains on Board section."""
    text = README.read_text()
    start = text.index(SECTION[0])
    section = text[start : text.index(SECTION[1], start)]
    steps: list[Step] = []
    for block in re.findall(r"```console\n(.*?)```", section, re.DOTALL):
        for line in block.splitlines():
            if line.startswith("$ "):
                command, _, comment = line[2:].partition("#")
                code = re.search(r"exit (\d+)", comment)
                cat = re.fullmatch(r"cat (\S+)", command.strip())
                steps.append(Step(command.strip(), int(code[1]) if code else 0,
                                  writes=cat[1] if cat else None))  # fmt: skip
            elif line.strip():
                steps[-1].shows.append(line)
    return steps


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


def test_every_command_of_the_bob_section_runs_as_shown(
    folders: dict[str, Path], tmp_path: Path
) -> None:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    for step in section_steps():
        if step.writes is not None:
            text = "\n".join(step.shows) + "\n"
            (tmp_path / step.writes).write_text(_located(text, folders))
            continue
        done = subprocess.run(
            ["bash", "-c", _located(step.command, folders)], cwd=tmp_path, env=env,
            capture_output=True, text=True, timeout=600, check=False,
        )  # fmt: skip
        assert done.returncode == step.exit_code, (step.command, done.stdout, done.stderr)
        for line in step.shows:
            assert line.strip() in done.stdout, (step.command, line, done.stdout)


def _located(text: str, folders: dict[str, Path]) -> str:
    """``text`` with the README's folders replaced by the test's."""
    for name, folder in folders.items():
        text = text.replace(name, str(folder))
    return text
