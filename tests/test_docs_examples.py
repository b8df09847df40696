"""The tutorials run as a reader runs them: every ``$`` line of their console blocks in a
process of its own, in a fresh folder per page (tests/console_blocks.py), its output checked for
the lines the page shows. The pages share one data cache, so the small room they home in is
generated once (:func:`data_cache`).

``$ pip install -e DIR`` is the one step not run as written: it would change the environment
every other test runs in. An editable install is a distribution record and the project's folder
on the path; the test makes both from the page's own ``pyproject.toml`` (its name, version and
entry points), in the test's folder.
"""

from __future__ import annotations

import os
import re
import shlex
import tomllib
from pathlib import Path

import pytest
from console_blocks import Step, console_steps, run_steps, user_env

pytestmark = pytest.mark.docs

TUTORIALS = Path(__file__).resolve().parents[1] / "docs" / "tutorials"
PAGES = sorted(TUTORIALS.glob("*.md"))


@pytest.fixture(scope="module")
def data_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One data cache for every page of this test run, shared by pytest-xdist's workers too
    (their base folders are siblings): the room is generated once (homebench generates into a
    temporary folder and renames it into place, so two workers generating it at once is safe)."""
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")
    base = tmp_path_factory.getbasetemp()
    folder = base.parent / f"docs-data-{run}" if run else base / "docs-data"
    folder.mkdir(exist_ok=True)
    return folder


def test_every_tutorial_has_commands_to_run() -> None:
    assert {page.stem for page in PAGES} >= {
        "tour",
        "plugin",
        "ci-smoke",
        "scale",
        "own-grid",
        "own-bob",
        "seed-001",
        "robots",
    }
    for page in PAGES:
        commands = [step.command for step in console_steps(page.read_text())]
        assert any(c.startswith("homebench ") for c in commands), page.name


def test_every_command_too_long_to_run_here_names_what_exists() -> None:
    """The ``bash`` blocks hold what CI cannot afford to run (the full experiments, a report):
    each ``homebench`` command there names a command and options that exist, and the configs
    it names are in the repository."""
    from homebench.cli import main

    root = TUTORIALS.parents[1]
    commands = [
        shlex.split(line)
        for page in PAGES
        for block in re.findall(r"```bash\n(.*?)```", page.read_text(), re.DOTALL)
        for command in block.splitlines()
        for line in command.split("&&")
        if line.strip().startswith("homebench ")
    ]
    assert commands
    for _, name, *args in commands:
        command = main.commands[name]
        options = {o for p in command.params for o in (*p.opts, *p.secondary_opts)}
        assert {a.partition("=")[0] for a in args if a.startswith("--")} <= options, args
        for arg in args:
            assert not arg.startswith("configs/") or (root / arg).is_file(), arg


@pytest.mark.parametrize("page", PAGES, ids=[page.stem for page in PAGES])
def test_every_command_of_a_tutorial_runs_as_shown(
    page: Path, data_cache: Path, tmp_path: Path
) -> None:
    site = tmp_path / ".site-packages"
    env = user_env({"HOMEBENCH_DATA": str(data_cache)})

    def install(step: Step) -> bool:
        project = re.fullmatch(r"pip install -e (\S+)", step.command)
        if project is None:
            return False
        folder = tmp_path / project[1]
        editable_install(folder, site)
        env["PYTHONPATH"] = os.pathsep.join(
            filter(None, [str(site), str(folder), env.get("PYTHONPATH")])
        )
        return True

    run_steps(console_steps(page.read_text()), tmp_path, env, handle=install)


def editable_install(project: Path, site: Path) -> None:
    """What ``pip install -e project`` leaves behind, in ``site``: the distribution's
    ``dist-info`` with its metadata and the entry points its ``pyproject.toml`` declares (the
    project's folder goes on the path)."""
    meta = tomllib.loads((project / "pyproject.toml").read_text())["project"]
    name, version = meta["name"], meta["version"]
    info = site / f"{name.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    groups = meta.get("entry-points", {})
    (info / "entry_points.txt").write_text(
        "".join(
            f"[{group}]\n" + "".join(f"{key} = {value}\n" for key, value in points.items())
            for group, points in groups.items()
        )
    )
