"""homebench's calls run with one BLAS / OpenMP thread in any process, and give the user's
settings back (homebench.methods.threads): the libraries' thread counts seen from inside a
method's call (threadpoolctl.threadpool_info, taken where the method computes) against those
outside, with a user's own limit of 3 threads (neither the machine's default nor 1)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from synthetic_panorama import render
from threadpoolctl import threadpool_info, threadpool_limits

from homebench.evaluation.isolation import THREAD_LIMITS
from homebench.geometry import Pose
from homebench.methods import registry
from homebench.methods.threads import CALLS
from homebench.methods.warping import method as warping

USER = 3  # the user's own setting


def _counts() -> list[int]:
    return [library["num_threads"] for library in threadpool_info()]


@pytest.fixture
def seen(monkeypatch: pytest.MonkeyPatch) -> list[list[int]]:
    """The thread counts seen inside warping's describe and home, one list per look."""
    looks: list[list[int]] = []

    def probe(function):
        def call(*args, **kwargs):
            looks.append(_counts())
            return function(*args, **kwargs)

        return call

    monkeypatch.setattr(warping, "horizon_signal", probe(warping.horizon_signal))
    monkeypatch.setattr(warping, "search_many", probe(warping.search_many))
    return looks


def test_one_thread_inside_a_call_and_the_users_setting_after(seen):
    method = registry.create("warping")
    with threadpool_limits(limits=USER):
        assert set(_counts()) == {USER}
        goal = method.describe(render(Pose(0.0, 0.0, 0.0)))
        current = method.describe(render(Pose(0.3, 0.2, 0.0)))
        assert set(_counts()) == {USER}
        method.home(current, goal)  # through home_many: nested calls
        assert set(_counts()) == {USER}
    assert len(seen) == 3 and all(set(look) == {1} for look in seen)


def test_the_users_setting_comes_back_after_a_call_that_raises():
    method = registry.create("warping")
    features = method.describe(render(Pose(0.0, 0.0, 0.0)))
    with threadpool_limits(limits=USER):
        with pytest.raises(ValueError, match="shape"):
            method.home(features[:-1], features)
        assert set(_counts()) == {USER}


def _plain_python(code: str, **environment: str) -> list[str]:
    """The lines ``code`` prints in a fresh interpreter without the thread variables (a
    user's script), with ``environment`` added."""
    plain = {k: v for k, v in os.environ.items() if k not in THREAD_LIMITS}
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**plain, **environment},
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


_VIEWS = """
import numpy as np
from threadpoolctl import threadpool_info
from homebench.geometry import PanoramaGeometry
from homebench.methods import registry
from homebench.methods.base import View
geometry = PanoramaGeometry.square_pixels(288, 0.8, -0.8)
image = np.random.default_rng(0).integers(0, 255, (geometry.height, 288), dtype=np.uint8)
views = [View(np.roll(image, 7 * k, axis=1), geometry) for k in range(5)]
def counts():
    return {i["filepath"]: i["num_threads"] for i in threadpool_info()}
"""


def test_calls_from_several_threads_share_the_limit():
    """The user's setting from the environment (3 threads: OpenBLAS takes at most a thread a
    core); three threads homing at once see one thread inside every call, and the setting is
    back when they are done."""
    code = (
        _VIEWS
        + """
import threading
from homebench.methods.warping import method as warping
seen = []
search = warping.search_many
def probe(*args):
    seen.append(set(counts().values()))
    return search(*args)
warping.search_many = probe
method = registry.create("warping")
goal, *currents = (method.describe(view) for view in views)
def work():
    for _ in range(20):
        method.home_many(currents, goal)
before = counts()
workers = [threading.Thread(target=work) for _ in range(3)]
for worker in workers:
    worker.start()
for worker in workers:
    worker.join()
print(len(seen), all(look == {1} for look in seen), counts() == before, set(before.values()))
"""
    )
    expected = f"60 True True {{{min(USER, os.cpu_count() or 1)}}}"
    assert _plain_python(code, OPENBLAS_NUM_THREADS=str(USER))[-1] == expected


def test_compiled_methods_start_no_numba_threads_and_leave_the_defaults():
    """In a plain process: the compiled methods' calls leave numba's threading layer unstarted
    and every BLAS library at its default (also those loaded during the calls: scipy's, which
    numba imports)."""
    code = (
        _VIEWS
        + """
import numba
before = counts()
for name, params in [("min-warping", {}), ("warping-2d", {}),
                     ("warping-2d", {"scheme": "scale-planes"}), ("block-matching", {})]:
    method = registry.create(name, **params)
    method.home(*(method.describe(view) for view in views[:2]))
after = counts()
try:
    numba.threading_layer()
    print("started")
except ValueError:
    print("not started")
print(set(after.values()) == set(before.values()) != {1})
"""
    )
    assert _plain_python(code)[-2:] == ["not started", "True"]


@pytest.mark.parametrize("name", sorted(registry.available()))
def test_every_registered_methods_calls_are_limited(name):
    cls = registry.get(name)
    calls = [call for call in CALLS if hasattr(cls, call)]
    assert {"describe", "home"} <= set(calls)
    for call in calls:
        assert getattr(getattr(cls, call), "single_threaded", False), f"{name}.{call}"
