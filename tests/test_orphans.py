"""Temporary files and half-generated worlds left by a killed process are removed on the next
start; those of a live process never are (issue 12)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from homebench.data.generate import generate, is_generated
from homebench.fileio import atomic_directory, atomic_write, write_text_atomic
from homebench.orphans import TMP_SUFFIX, remove_orphans

TESTS = Path(__file__).resolve().parent
HOUR_AGO = time.time() - 3600

#: Holds a temporary file and a temporary world folder open until ``go`` appears.
HOLDER = """
import sys, time
from pathlib import Path
from homebench.fileio import atomic_directory, atomic_write
folder = Path(sys.argv[1])
with atomic_write(folder / "result.json") as f, atomic_directory(folder / "world") as tmp:
    f.write(b"{}")
    (tmp / "0_0.png").write_bytes(b"half")
    (folder / "ready").touch()
    while not (folder / "go").exists():
        time.sleep(0.02)
"""

#: Generates the small world of test_generate into ``folder/world``, waiting for ``go``.
GENERATOR = f"""
import sys, time
from pathlib import Path
sys.path.insert(0, {str(TESTS)!r})
from test_generate import FakeRenderer, small_spec
from homebench.data.generate import generate
folder = Path(sys.argv[1])

class Waiting(FakeRenderer):
    def render_position(self, spec, i, j):
        (folder / "ready").touch()
        while not (folder / "go").exists():
            time.sleep(0.02)
        return super().render_position(spec, i, j)

print(generate(small_spec(), folder / "world", renderer=Waiting()))
"""


def _start(script: str, folder: Path) -> subprocess.Popen[str]:
    process = subprocess.Popen(
        [sys.executable, "-c", script, str(folder)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not (folder / "ready").exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.02)
    return process


@pytest.fixture
def processes() -> Iterator[list[subprocess.Popen[str]]]:
    """Subprocesses of a test, killed at its end whatever happens."""
    started: list[subprocess.Popen[str]] = []
    yield started
    for process in started:
        if process.poll() is None:
            process.kill()
            process.wait()


def _temporaries(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.name.endswith(TMP_SUFFIX))


def _age(paths: list[Path]) -> None:
    for path in paths:
        os.utime(path, (HOUR_AGO, HOUR_AGO), follow_symlinks=False)


def test_orphans_of_a_killed_process_go_at_the_next_start(
    tmp_path: Path, processes: list[subprocess.Popen[str]]
) -> None:
    processes.append(holder := _start(HOLDER, tmp_path))
    orphans = _temporaries(tmp_path)
    assert len(orphans) == 2 and any(p.is_dir() for p in orphans)
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    _age(orphans)
    write_text_atomic(tmp_path / "next.json", "{}")  # the next start writes into the folder
    assert sorted(p.name for p in tmp_path.iterdir()) == ["next.json", "ready"]


def test_a_killed_generation_is_cleaned_by_the_next(
    tmp_path: Path, processes: list[subprocess.Popen[str]]
) -> None:
    from test_generate import FakeRenderer, small_spec

    processes.append(generator := _start(GENERATOR, tmp_path))
    generator.send_signal(signal.SIGKILL)
    generator.wait()
    (half,) = _temporaries(tmp_path)
    _age([half])
    final = generate(small_spec(), tmp_path / "world", renderer=FakeRenderer())
    assert is_generated(final, small_spec())
    assert not half.exists() and _temporaries(tmp_path) == []


def test_a_concurrent_generation_of_the_same_world_is_not_broken(
    tmp_path: Path, processes: list[subprocess.Popen[str]]
) -> None:
    from test_generate import FakeRenderer, small_spec

    processes.append(other := _start(GENERATOR, tmp_path))
    (theirs,) = _temporaries(tmp_path)
    _age([theirs])  # looks abandoned by its age, but its process is alive and holds it
    final = generate(small_spec(), tmp_path / "world", renderer=FakeRenderer())
    assert theirs.is_dir() and (theirs / "raw").is_dir()
    (tmp_path / "go").touch()
    out, err = other.communicate(timeout=60)
    assert other.returncode == 0, err
    assert Path(out.strip()) == final and is_generated(final, small_spec())
    assert _temporaries(tmp_path) == []


def test_the_rule_age_lock_name_and_kind(tmp_path: Path) -> None:
    with atomic_write(tmp_path / "live.json") as live, atomic_directory(tmp_path / "dir"):
        live.write(b"{}")
        held = _temporaries(tmp_path)
        _age(held)
        orphan = tmp_path / ".dead.json.abcd_123.homebench.tmp"
        young = tmp_path / ".young.json.abcd_123.homebench.tmp"
        foreign = [tmp_path / n for n in (".x.abcd_123.tmp", "x.abcd_123.homebench.tmp", ".x.tmp")]
        for path in (orphan, young, *foreign):
            path.write_text("x")
        link = tmp_path / ".link.abcd_123.homebench.tmp"
        link.symlink_to(orphan)
        _age([orphan, *foreign, link])
        assert remove_orphans(tmp_path) == [orphan]
        assert all(p.exists() for p in (*held, young, *foreign)) and link.is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name in ("live.json", "dir")) == [
        "dir",
        "live.json",
    ]
