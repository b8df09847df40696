"""Console blocks of a Markdown text, run as a user runs them (the README's sections, the
documentation's tutorials).

Every ``$`` line of a ```` ```console ```` block is a shell command run in a process of its own.
A ``$ cat FILE`` line is followed by the file's text, which the runner writes (its folders
made); any other line under a command is text its output must hold, and a line ending in
``...`` only its start (a table row whose timings differ from machine to machine); ``# exit N``
in a command's comment is its exit code (0 otherwise).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

#: Marks a shown line that the output need only start with (up to this mark).
PREFIX_MARK = "..."


@dataclass
class Step:
    """A ``$`` line: its ``command``, the exit code it expects, the output lines it shows, or
    the file it shows (``cat``) and that file's lines."""

    command: str
    exit_code: int = 0
    shows: list[str] = field(default_factory=list)
    writes: str | None = None


def console_steps(markdown: str) -> list[Step]:
    """The steps of every console block of ``markdown``, in order."""
    steps: list[Step] = []
    for block in re.findall(r"```console\n(.*?)```", markdown, re.DOTALL):
        for line in block.splitlines():
            if line.startswith("$ "):
                command, _, comment = line[2:].partition("#")
                code = re.search(r"exit (\d+)", comment)
                cat = re.fullmatch(r"cat (\S+)", command.strip())
                steps.append(Step(command.strip(), int(code[1]) if code else 0,
                                  writes=cat[1] if cat else None))  # fmt: skip
            elif line.strip() or (steps and steps[-1].writes is not None):
                steps[-1].shows.append(line)
    return steps


def section(markdown: str, start: str, stop: str) -> str:
    """The text of ``markdown`` from the heading ``start`` to the heading ``stop``."""
    begin = markdown.index(start)
    return markdown[begin : markdown.index(stop, begin)]


def user_env(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment a user's shell has: this interpreter's scripts (``homebench``) first on
    the PATH, and ``extra``."""
    path = f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"
    return {**os.environ, "PATH": path, **(extra or {})}


def run_steps(
    steps: list[Step],
    cwd: Path,
    env: Mapping[str, str],
    located: Callable[[str], str] = lambda text: text,
    handle: Callable[[Step], bool] = lambda step: False,
) -> None:
    """Run ``steps`` in ``cwd`` and check each one's exit code and output. ``located``
    rewrites a command's and a file's text (a page's folders as the test's); ``handle`` may
    take a step over (and say so by returning True): one that cannot run as written here."""
    for step in steps:
        if step.writes is not None:
            target = cwd / step.writes
            target.parent.mkdir(parents=True, exist_ok=True)
            text = "\n".join(step.shows).strip("\n")
            target.write_text(located(text + "\n" if text else ""))
            continue
        if handle(step):
            continue
        done = subprocess.run(
            ["bash", "-c", located(step.command)], cwd=cwd, env=dict(env),
            capture_output=True, text=True, timeout=600, check=False,
        )  # fmt: skip
        assert done.returncode == step.exit_code, (step.command, done.stdout, done.stderr)
        for line in step.shows:
            assert shown(line, done.stdout), (step.command, line, done.stdout)


def shown(line: str, output: str) -> bool:
    """Whether ``output`` holds the shown ``line`` (its start, when it ends in ``...``)."""
    text = line.strip()
    if text.endswith(PREFIX_MARK):
        text = text[: -len(PREFIX_MARK)].rstrip()
    return text in output
