"""The documentation site builds (``mkdocs build --strict``: no broken link, no missing page) and
its generated reference holds what the code holds: every command and option (click's own
tree), every key of the run configs and the manifest (the pydantic models, nested ones
included), every method's every parameter (the registry), every metric's definition."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from html import escape as html_text
from pathlib import Path
from typing import Any, get_args

import click
import pytest
from pydantic import BaseModel

pytestmark = pytest.mark.docs
pytest.importorskip("mkdocs", reason="the docs extra: pip install -e '.[docs]'")

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "-d", str(out),
         "-f", str(ROOT / "mkdocs.yml")],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return out


def _page(site: Path, path: str) -> str:
    return (site / path / "index.html").read_text()


def _commands(group: click.Command, path: str = "homebench") -> Iterator[tuple[str, Any]]:
    yield path, group
    for name, command in getattr(group, "commands", {}).items():
        yield from _commands(command, f"{path} {name}")


def test_every_command_and_option_is_in_the_command_reference(site: Path) -> None:
    from homebench.cli import main

    html = _page(site, "reference/cli")
    for path, command in _commands(main):
        assert f">{path}<" in html, path
        for param in command.params:
            if isinstance(param, click.Option):
                for flag in param.opts + param.secondary_opts:
                    assert flag in html, (path, flag)


def _models(root: type[BaseModel]) -> Iterator[type[BaseModel]]:
    """``root`` and every model its fields' types name, at any depth."""
    seen: set[type] = set()
    stack: list[Any] = [root]
    while stack:
        hint = stack.pop()
        if isinstance(hint, type) and issubclass(hint, BaseModel):
            if hint in seen:
                continue
            seen.add(hint)
            yield hint
            stack.extend(field.annotation for field in hint.model_fields.values())
        else:
            stack.extend(arg for arg in get_args(hint) if not isinstance(arg, str))


#: Each schema reference page and the root models it documents ("module:Class").
SCHEMAS = [
    ("reference/config", ["homebench.config:RunConfig",
                          "homebench.experiments.route.config:RouteConfig",
                          "homebench.experiments.closed_loop.config:ClosedLoopConfig"]),
    ("reference/manifest", ["homebench.data.manifest:Manifest"]),
]  # fmt: skip


def _roots(roots: list[str]) -> list[type[BaseModel]]:
    """The classes ``roots`` ("module:Class") name."""
    import importlib

    return [
        getattr(importlib.import_module(module), name)
        for module, _, name in (root.partition(":") for root in roots)
    ]


@pytest.mark.parametrize(("page", "roots"), SCHEMAS)
def test_every_key_of_a_schema_is_in_its_reference(site: Path, page: str, roots: list[str]):
    html = _page(site, page)
    for root in _roots(roots):
        for model in _models(root):
            assert f'id="{model.__name__.lower()}"' in html, model.__name__
            for key, field in model.model_fields.items():
                assert f"<code>{field.alias or key}</code>" in html, (model.__name__, key)


@pytest.mark.parametrize(("page", "roots"), SCHEMAS)
def test_every_key_of_a_schema_has_a_description(page: str, roots: list[str]) -> None:
    """Each row of a schema page (docs/hooks/schema.py's, as the page is built) says what its
    key means: a ``Field(description=...)`` or a comment on or above the field."""
    sys.path.insert(0, str(ROOT / "docs" / "hooks"))
    try:
        import schema
    finally:
        sys.path.remove(str(ROOT / "docs" / "hooks"))
    undescribed = [
        f"{cls.__module__}.{cls.__name__}.{key.name}"
        for cls in schema.reachable(_roots(roots))
        for key in schema.keys(cls)
        if not key.description.strip()
    ]
    assert not undescribed, f"{page}: keys without a description: {undescribed}"


def test_every_method_parameter_is_in_the_method_reference(site: Path) -> None:
    from homebench.methods import registry

    html = _page(site, "reference/methods")
    for name in registry.available():
        assert f'id="{name}"' in html, name
        for parameter in registry.parameters(name):
            assert f"<code>{parameter}</code>" in html, (name, parameter)
    assert "<code>compass</code>" in html  # the entry-level key


def test_every_definition_is_in_the_metrics_reference(site: Path) -> None:
    from homebench.config import MetricsConfig
    from homebench.report.definitions import definitions

    html = _page(site, "reference/definitions")
    for heading in definitions(MetricsConfig()):
        assert f">{html_text(heading, quote=False)}<" in html, heading


def test_the_tour_shows_its_figure(site: Path) -> None:
    html = _page(site, "tutorials/tour")
    assert 'src="../img/tour-fields-day.png"' in html
    assert (site / "tutorials" / "img" / "tour-fields-day.png").is_file()
