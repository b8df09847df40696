"""The keys of a pydantic model or a ``TypedDict`` as rows (key, type, default, bounds,
description), and the models it refers to: the documentation's schema tables, read from the
code at build time.

A key's description is its ``Field(description=...)``, else the comments the code gives it: a
block of comment lines right above the field and a comment at the end of its line(s).
"""

from __future__ import annotations

import ast
import inspect
import io
import re
import textwrap
import tokenize
import types
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal, get_args, get_origin

import yaml
from pydantic import BaseModel
from pydantic_core import PydanticUndefined
from typing_extensions import is_typeddict

from homebench.methods.param_types import bounds_text

_UNIONS = (typing.Union, types.UnionType)


@dataclass(frozen=True)
class Key:
    """One key of a schema: what a reader needs to write it."""

    name: str
    type: str
    default: str
    bounds: str
    description: str


def is_schema(hint: Any) -> bool:
    """Whether ``hint`` is a class whose keys this module lists (a model or a TypedDict)."""
    return inspect.isclass(hint) and (issubclass(hint, BaseModel) or is_typeddict(hint))


def _hints(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls, include_extras=True)


def _unwrap(hint: Any) -> Any:
    """``hint`` without ``NotRequired`` / ``Required`` around it."""
    while get_origin(hint) in (typing.NotRequired, typing.Required):
        hint = get_args(hint)[0]
    return hint


def type_text(hint: Any, link: bool = True) -> str:
    """A type hint in words, Markdown: models and TypedDicts as links to their sections."""
    hint = _unwrap(hint)
    origin, args = get_origin(hint), get_args(hint)
    if origin is Annotated:
        return type_text(args[0], link)
    if origin is Literal:
        return " or ".join(f"`{choice}`" for choice in args)
    if origin in _UNIONS:
        return " or ".join("`null`" if a is type(None) else type_text(a, link) for a in args)
    if origin in (list, tuple, set, frozenset):
        items = [a for a in args if a is not Ellipsis]
        if origin is tuple and len(items) > 1 and Ellipsis not in args:
            return "[" + ", ".join(type_text(a, link) for a in items) + "]"
        inner = type_text(items[0], link) if items else "any"
        return f"list of {inner}"
    if origin is dict:
        return f"mapping of {type_text(args[0], link)} to {type_text(args[1], link)}"
    if hint is Any:
        return "any"
    if hint is Path:
        return "path"
    if is_schema(hint):
        return f"[{hint.__name__}](#{hint.__name__.lower()})" if link else hint.__name__
    return f"`{getattr(hint, '__name__', str(hint))}`"


def referenced(hint: Any) -> Iterator[type]:
    """The models and TypedDicts a type hint refers to, at any depth of its arguments."""
    hint = _unwrap(hint)
    if is_schema(hint):
        yield hint
    for arg in get_args(hint):
        if not isinstance(arg, str | int | float | bool | type(None)) or inspect.isclass(arg):
            yield from referenced(arg)


def _bounds(hint: Any, metadata: list[Any]) -> str:
    """The bounds of a key: its field's markers and those of ``Annotated`` types within."""
    parts = [bounds_text(Annotated[object, *metadata])] if metadata else []
    parts += [f"at least {m.min_length} items" for m in metadata if getattr(m, "min_length", 0)]
    stack = [_unwrap(hint)]
    while stack:
        each = stack.pop()
        if get_origin(each) is Annotated:
            parts.append(bounds_text(each))
            pattern = [getattr(m, "pattern", None) for m in get_args(each)[1:]]
            parts += [f"matches `{p}`" for p in pattern if p]
            stack.append(get_args(each)[0])
        elif get_origin(each) in _UNIONS:
            stack.extend(get_args(each))
    return "; ".join(dict.fromkeys(p for p in parts if p))


def _yaml_value(value: Any) -> Any:
    """``value`` as plain data YAML writes: tuples as lists, paths as text, models as dicts."""
    if isinstance(value, BaseModel):
        return value.model_dump(mode="json", exclude_defaults=True)
    if isinstance(value, list | tuple):
        return [_yaml_value(v) for v in value]
    if isinstance(value, dict):
        return {k: _yaml_value(v) for k, v in value.items()}
    return str(value) if isinstance(value, Path) else value


def _default_text(value: Any) -> str:
    """A default as a config writes it (``null``, ``[]``, ``{method: klt-sector}``)."""
    if isinstance(value, BaseModel):
        return f"its section's defaults ({type(value).__name__})"
    try:
        text = yaml.safe_dump(_yaml_value(value), default_flow_style=True, width=1000)
    except yaml.YAMLError:
        return f"`{value!r}`"
    return f"`{text.removesuffix(chr(10)).removesuffix('...').strip()}`"


def comments(cls: type) -> dict[str, str]:
    """Per field of class ``cls``, the comment block above it and the comment on its lines."""
    try:
        source = textwrap.dedent(inspect.getsource(cls))
    except (OSError, TypeError):
        return {}
    lines = source.splitlines()
    notes: dict[int, str] = {}
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            notes[token.start[0]] = token.string.lstrip("#").strip()
    body = ast.parse(source).body[0]
    out = {}
    for node in getattr(body, "body", []):
        if not (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)):
            continue
        above = []
        row = node.lineno - 1
        while row >= 1 and lines[row - 1].strip().startswith("#"):
            above.insert(0, notes.get(row, ""))
            row -= 1
        after = [notes[r] for r in range(node.lineno, node.end_lineno + 1) if r in notes]
        text = " ".join(part for part in [*above, *after] if part and "fmt:" not in part)
        if text:
            out[node.target.id] = text
    return out


def _field_comments(cls: type) -> dict[str, str]:
    """:func:`comments` of ``cls`` and of the classes it inherits fields from."""
    out: dict[str, str] = {}
    for base in reversed(cls.__mro__):
        if base.__module__ not in ("builtins", "typing", "typing_extensions"):
            out.update(comments(base))
    return out


def keys(cls: type) -> list[Key]:
    """The keys of model or TypedDict ``cls``, in the order the class declares them."""
    notes = _field_comments(cls)
    if is_typeddict(cls):
        optional = getattr(cls, "__optional_keys__", frozenset())
        return [
            Key(name, type_text(hint), "optional" if name in optional else "required",
                _bounds(hint, []), notes.get(name, ""))
            for name, hint in _hints(cls).items()
        ]  # fmt: skip
    hints = _hints(cls)
    rows = []
    for name, field in cls.model_fields.items():
        hint = hints.get(name, field.annotation)
        if field.default is not PydanticUndefined:
            default = _default_text(field.default)
        elif field.default_factory is not None:
            default = _default_text(field.default_factory())  # type: ignore[call-arg]
        else:
            default = "required"
        description = field.description or notes.get(name, "")
        rows.append(
            Key(field.alias or name, type_text(hint), default, _bounds(hint, field.metadata),
                description)
        )  # fmt: skip
    return rows


def reachable(roots: list[type]) -> list[type]:
    """``roots`` and every model or TypedDict their keys refer to, each once, roots first."""
    seen: list[type] = []
    queue = list(roots)
    while queue:
        cls = queue.pop(0)
        if cls in seen:
            continue
        seen.append(cls)
        for hint in _hints(cls).values():
            queue.extend(c for c in referenced(hint) if c not in seen)
    return seen


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_doc(doc: str) -> str:
    """A docstring as Markdown: reStructuredText roles and literals as code, a literal block's
    ``::`` as ``:`` (its indented lines are a Markdown code block already)."""
    doc = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", inspect.cleandoc(doc))
    doc = re.sub(r"::$", ":", doc, flags=re.M)
    return re.sub(r"``([^`]+)``", r"`\1`", doc)


def plain_doc(cls: type) -> str:
    """A class docstring as Markdown (:func:`markdown_doc`)."""
    if not cls.__doc__ or cls.__doc__.startswith(f"{cls.__name__}("):
        return ""  # no docstring, or the one dataclasses generate
    return "" if cls.__doc__ == BaseModel.__doc__ else markdown_doc(cls.__doc__)


def module_doc(cls: type) -> str:
    """The docstring of the module that defines ``cls``, as Markdown."""
    doc = getattr(inspect.getmodule(cls), "__doc__", None)
    return markdown_doc(doc) if doc else ""


def section(cls: type, level: int = 2) -> str:
    """A model's section: heading (its name), docstring, and a table of its keys."""
    rows = [
        f"| `{k.name}` | {_cell(k.type)} | {_cell(k.default)} | {_cell(k.bounds)} | "
        f"{_cell(k.description)} |"
        for k in keys(cls)
    ]
    return "\n".join(
        [
            f"{'#' * level} {cls.__name__}",
            "",
            plain_doc(cls),
            "",
            "| key | type | default | bounds | description |",
            "| --- | --- | --- | --- | --- |",
            *rows,
            "",
        ]
    )
