"""Real small or read-only file systems for tests: a tmpfs mounted for the test (mounting
needs root; where it cannot be done the caller skips or falls back)."""

from __future__ import annotations

import contextlib
import subprocess
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def tmpfs(folder: Path, options: str) -> Iterator[str]:
    """Mount a tmpfs with ``options`` ("size=1m", "ro,size=64k") on the existing ``folder``
    for the block; yields "" when mounted, else why it could not be."""
    command = ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, check=False)
    except FileNotFoundError:
        yield "no mount command"
        return
    if done.returncode != 0:
        yield f"cannot mount a tmpfs here: {done.stderr.strip()}"
        return
    try:
        yield ""
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)
