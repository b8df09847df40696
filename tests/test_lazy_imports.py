"""numba is imported only where compiled kernels run: not by the command line, which imports
every method module to list and check them, and once per run by the worker server of the
methods that need it (their ``preload_modules``), not by each worker."""

from __future__ import annotations

import subprocess
import sys

from homebench.config import MethodEntry
from homebench.evaluation.executors import PRELOAD, preload_for
from homebench.methods import registry

BUILT_IN = sorted(registry.available())


def _python(code: str, timeout_s: float = 120.0) -> str:
    """What ``code`` prints when run by a fresh interpreter (which must succeed)."""
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout_s, check=False
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_listing_and_checking_methods_does_not_import_numba() -> None:
    code = (
        "import sys\n"
        "from click.testing import CliRunner\n"
        "from homebench.cli import main\n"
        "import homebench.evaluation.runner, homebench.evaluation.jobs\n"
        "result = CliRunner().invoke(main, ['methods'])\n"
        "assert result.exit_code == 0, result.output\n"
        "assert 'min-warping' in result.output and 'klt-sector' in result.output\n"
        "print(sorted(m for m in sys.modules if m.partition('.')[0] == 'numba')[:3])\n"
    )
    imported = _python(code)
    assert imported == "[]", f"numba was imported: {imported}"


def test_methods_that_run_numba_kernels_name_them_in_preload_modules() -> None:
    """Every built-in describes and homes one pair in a fresh process, those without
    ``preload_modules`` first: none of them may import numba (its workers would each import
    it), each of the others does (else its preload is wasted)."""
    code = (
        "import sys\n"
        "from homebench.data.synth.spec import WorldSpec\n"
        "from homebench.data.synth.world import render_position\n"
        "from homebench.methods import registry\n"
        "from homebench.methods.base import View\n"
        "spec = WorldSpec(grid={'shape': [3, 3]})\n"
        "def view(kind, position):\n"
        "    image = render_position(spec, *position)[kind]\n"
        "    camera = spec.raw if kind == 'raw' else spec.unfolded\n"
        "    return View(image, camera.geometry())\n"
        "names = sorted(registry.available(), key=lambda n: (\n"
        "    bool(getattr(registry.get(n), 'preload_modules', ())), n))\n"
        "for name in names:\n"
        "    method = registry.create(name)\n"
        "    kind = method.image_kind\n"
        "    current, goal = (method.describe(view(kind, p)) for p in ((0, 0), (1, 1)))\n"
        "    method.home(current, goal)\n"
        "    print(name, 'numba' in sys.modules)\n"
    )
    imported = dict(line.split() for line in _python(code, 300.0).splitlines())
    assert set(imported) == set(BUILT_IN)
    for name, numba in imported.items():
        declares = bool(getattr(registry.get(name), "preload_modules", ()))
        assert (numba == "True") == declares, f"{name}: numba imported {numba}"


def _entries(*names: str) -> list[MethodEntry]:
    return [MethodEntry(method=name) for name in names]


def test_the_preload_of_a_run_adds_only_its_methods_kernels() -> None:
    assert preload_for(_entries("warping", "sift", "warping")) == PRELOAD
    assert preload_for(_entries("min-warping", "klt-sector", "min-warping")) == (
        *PRELOAD,
        "homebench.methods.min_warping.kernels",
        "homebench.methods.min_warping.preload",
        "homebench.methods.jit_setup",
        "homebench.methods.klt_sector.sector_law_kernels",
    )


def test_the_preloaded_kernels_import_numba() -> None:
    code = (
        "import importlib, sys\n"
        "from homebench.evaluation.executors import preload_for\n"
        "from homebench.config import MethodEntry\n"
        "entries = [MethodEntry(method=m) for m in ('min-warping', 'klt-sector')]\n"
        "for module in preload_for(entries):\n"
        "    importlib.import_module(module)\n"
        "print('numba' in sys.modules)\n"
    )
    assert _python(code) == "True"
