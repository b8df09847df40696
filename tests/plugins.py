"""Test plugins installed as real distributions: a module and a ``*.dist-info`` folder with an
entry point of the group ``homebench.methods``, on ``sys.path`` (spawned workers and Dask workers
inherit it) and ``PYTHONPATH`` (for commands run in a subprocess). Every plugin gets a fresh
module and method name, so tests never see another test's plugin."""

from __future__ import annotations

import itertools
import os
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

from homebench.methods import registry

_COUNTER = itertools.count()

#: A homing method that fails on purpose: it raises on every pair of a chosen goal (views are
#: named by their mean grey level, its features), segfaults or hangs on a chosen goal's first
#: pair, exhausts memory on a chosen (goal, current) pair and raises on a chosen current view;
#: otherwise it answers a fixed direction.
FAULTY = '''
"""Fault injection for homebench's tests."""

from __future__ import annotations

import os
import signal
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homebench.methods.base import HomingEstimate


@dataclass(frozen=True)
class Faulty:
    """Test method: fails on purpose on chosen goals."""

    name: ClassVar[str] = "{name}"
    image_kind: ClassVar[str] = "unfolded"
    raise_goal: float = -1.0
    segfault_goal: float = -1.0
    hang_goal: float = -1.0
    oom_pair: tuple = ()
    raise_current: float = -1.0

    def describe(self, view):
        return float(np.mean(view.image))

    def home(self, current, goal):
        if goal == self.raise_goal:
            raise RuntimeError("simulated failure in home")
        if goal == self.segfault_goal:
            os.kill(os.getpid(), signal.SIGSEGV)
        if goal == self.hang_goal:
            time.sleep(3600)
        if [goal, current] == list(self.oom_pair):
            hoard = []
            while True:
                hoard.append(np.ones(1 << 26, dtype=np.uint8))
        if current == self.raise_current:
            raise ValueError("simulated failure of one pair")
        return HomingEstimate(angle=0.1, n_landmarks=1)
'''


@dataclass(frozen=True)
class Plugin:
    """An installed test plugin: its module file, method name and distribution name."""

    path: Path
    method: str
    distribution: str


def install_plugin(
    folder: Path, monkeypatch: pytest.MonkeyPatch, source: str = FAULTY, version: str = "1.0"
) -> Plugin:
    """Install ``source`` (``{name}`` filled with a fresh method name) as the distribution
    ``plugin-<n>`` whose entry point names the module's ``Faulty``."""
    n = next(_COUNTER)
    module, dist, method = f"homebench_test_plugin_{n}", f"plugin-{n}", f"faulty-{n}"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{module}.py"
    path.write_text(textwrap.dedent(source).replace("{name}", method))
    info = folder / f"plugin_{n}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(f"[homebench.methods]\n{method} = {module}:Faulty\n")
    monkeypatch.syspath_prepend(str(folder))
    registry.names()  # built-ins register into the real registry, before it is copied
    for state in ("_REGISTRY", "_FEATURES", "_BROKEN", "_PLUGINS"):  # this test's plugins only
        monkeypatch.setattr(registry, state, dict(getattr(registry, state)))
    paths = [str(folder), *filter(None, [os.environ.get("PYTHONPATH")])]
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(paths))  # for `python -m homebench`
    return Plugin(path, method, dist)
