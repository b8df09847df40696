"""Job and feature keys hold everything that determines a result: the method's code version,
the images' content and the parameters. A changed method or image recomputes; the rest is
reused."""

from __future__ import annotations

import shutil
import textwrap
from dataclasses import replace
from pathlib import Path

import pandas as pd
import pytest
from conftest import arena_config, run_config
from plugins import install_plugin

from homebench.config import RunConfig
from homebench.evaluation.code_version import code_version, source_closure
from homebench.evaluation.plan import ImageInputs, make_plan
from homebench.evaluation.sources import prepare_sources
from homebench.fileio import read_grey, write_png
from homebench.methods import registry


def _config(folder: Path, manifest: Path, method: str) -> dict:
    methods = [{"method": method}, {"method": "warping", "params": {"n_rho": 4}}]
    return arena_config(folder, manifest, methods=methods)


def test_an_edited_plugin_recomputes_and_an_unchanged_one_does_not(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugin = install_plugin(tmp_path / "plugin", monkeypatch)
    config = _config(tmp_path, arena_manifest, plugin.method)
    assert run_config(tmp_path, config).exit_code == 0
    result = run_config(tmp_path, config)
    assert result.exit_code == 0 and "0 job(s) computed, 4 reused" in result.stdout
    before = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    source = plugin.path.read_text()
    plugin.path.write_text(source.replace("angle=0.1", "angle=0.2"))
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "2 job(s) computed, 2 reused" in result.stdout
    after = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    faulty = after["method"] == plugin.method
    assert (after.loc[faulty, "estimate_rad"] == 0.2).all()
    assert (before.loc[faulty, "estimate_rad"] == 0.1).all()


def test_a_changed_image_recomputes_the_jobs_that_see_it(
    tmp_path: Path, arena_manifest: Path
) -> None:
    database = tmp_path / "arena"
    shutil.copytree(arena_manifest.parent, database)
    config = arena_config(tmp_path, database / "manifest.yaml", goals=[[0, 0]])
    assert run_config(tmp_path, config).exit_code == 0
    image = database / "pano" / "p2-3.png"
    write_png(image, 255 - read_grey(image))
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "2 job(s) computed, 0 reused" in result.stdout


def _package(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))


#: Modules imported in statements nested in functions, classes, handlers, loops and cases.
NESTED = ("in_case", "in_else", "in_handler", "in_try", "in_with")


def test_source_closure_follows_imports_within_the_package_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _package(
        tmp_path,
        {
            "toypkg/__init__.py": "",
            "toypkg/method.py": """
                import os
                from toypkg import helper
                from .sub.deep import thing

                def run():
                    import toypkg.lazy

                class Method:
                    def home(self, kind):
                        try:
                            import toypkg.in_try
                        except ImportError:
                            from toypkg import in_handler
                        finally:
                            with open(kind) as f:
                                import toypkg.in_with
                        for _ in range(2):
                            while kind:
                                if kind:
                                    pass
                                else:
                                    import toypkg.in_else
                        match kind:
                            case "a":
                                import toypkg.in_case
                        return [x for x in (lambda: __import__("toypkg.dynamic"),)]
            """,
            "toypkg/helper.py": "from . import base\n",
            "toypkg/base.py": "X = 1\n",
            "toypkg/lazy.py": "",
            **{f"toypkg/{name}.py": "" for name in NESTED},
            "toypkg/dynamic.py": "",
            "toypkg/sub/__init__.py": "",
            "toypkg/sub/deep.py": "thing = 2\n",
            "toypkg/unrelated.py": "import toypkg.method\n",
        },
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    closure = source_closure("toypkg.method")
    assert sorted(closure) == [
        "toypkg.base",
        "toypkg.helper",
        *(f"toypkg.{name}" for name in NESTED),
        "toypkg.lazy",
        "toypkg.method",
        "toypkg.sub.deep",
    ]


def test_an_optional_package_that_is_not_installed_is_no_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The README's install has no extras: a module that imports an optional package in a
    function (``dask`` in the executors) still has a code version."""
    _package(
        tmp_path,
        {
            "toypkg/__init__.py": "",
            "toypkg/method.py": """
                from toypkg import base

                def on_a_cluster():
                    from not_installed_optional.distributed import Client
                    import not_installed_optional.sub
            """,
            "toypkg/base.py": "X = 1\n",
        },
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    assert sorted(source_closure("toypkg.method")) == ["toypkg.base", "toypkg.method"]


def test_builtin_code_version_is_the_package_version_and_a_source_hash() -> None:
    version = code_version(registry.get("warping"))
    assert version.startswith("homebench ")
    assert version == code_version(registry.get("warping"))
    assert version != code_version(registry.get("sift"))
    assert "homebench.methods.sift.method" not in source_closure("homebench.methods.warping.method")


def test_image_tasks_are_equal_and_hash_alike_exactly_when_their_inputs_are(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """Planning and the runner's sets compare tasks by their inputs: a task of an equal source
    loaded again is the same task; another position, rotation or content is not."""
    config = RunConfig.model_validate(
        arena_config(tmp_path, arena_manifest, goals=[[1, 2]], methods=[{"method": "warping"}])
    )
    (job,) = make_plan(config, prepare_sources(config, 1), tmp_path / "config.yaml").home
    (again,) = make_plan(config, prepare_sources(config, 1), tmp_path / "config.yaml").home
    task, same = job.currents[3], again.currents[3]
    assert task.source is not same.source
    assert task == same and hash(task) == hash(same) == hash(task.inputs)
    assert task.inputs == ImageInputs(
        task.source.identity, task.i, task.j, task.rotation, task.content
    )
    others = [
        job.currents[4],
        replace(task, rotation=0.5),
        replace(task, content="another"),
        replace(task, source=replace(task.source, identity="another")),
    ]
    assert all(task != other and task.inputs != other.inputs for other in others)
    assert len({task, same, *others}) == 1 + len(others)


def test_a_real_sets_database_key_is_its_images_content_not_its_folder(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """Two copies of a database in other folders are the same database (runs over them pair
    up in ``compare``); an edited image makes another."""

    def database_key(manifest: Path) -> str:
        config = RunConfig.model_validate(arena_config(tmp_path, manifest))
        return next(iter(prepare_sources(config, 1).values())).database_key

    copy = tmp_path / "copy"
    shutil.copytree(arena_manifest.parent, copy)
    assert database_key(copy / "manifest.yaml") == database_key(arena_manifest)
    image = copy / "pano" / "p0-0.png"
    write_png(image, 255 - read_grey(image))
    assert database_key(copy / "manifest.yaml") != database_key(arena_manifest)


def test_the_rr_reading_of_an_abstention_leaves_every_job_key_alone(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """RR is computed from the stored pairs: metrics.return_ratio.no_estimate changes the
    tables (run ``--update``), never a job."""
    given = arena_config(tmp_path, arena_manifest, goals=[[1, 2]], methods=[{"method": "warping"}])
    configs = [
        RunConfig.model_validate({**given, "metrics": {"return_ratio": {"no_estimate": reading}}})
        for reading in ("fail", "arrived")
    ]
    sources = prepare_sources(configs[0], 1)  # the same databases
    keys = [
        sorted(job.key for job in make_plan(config, sources, tmp_path / "config.yaml").home)
        for config in configs
    ]
    assert keys[0] == keys[1]
