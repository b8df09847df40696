"""Method parameters that say what they mean and how they stand to the method's paper.

A method's parameters are its dataclass fields. :func:`param` makes such a field and records its
meaning, and, when it has one, its relation to the paper:

- ``paper=``: the field is a **departure** homebench offers as an opt-in option; the default is
  the paper's behaviour and the text says what the paper does (and why the option exists).
- ``reading=``: the paper is ambiguous here (or names no value); the text says which reading
  homebench implements and why.

A field with neither is the paper's own parameter (or an implementation setting the paper has no
use for). :func:`parameter_docs` reads any method's fields — third-party methods without metadata
included — and :mod:`homebench.methods.cards` formats them for ``homebench methods`` and the
documentation; :func:`documented` appends the same list to the class docstring, so the reasons
live in one place. The values a method is given are checked against its fields' types by
:mod:`homebench.methods.param_types`.
"""

from __future__ import annotations

import dataclasses
import re
import textwrap
import types
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal, get_args, get_origin

from homebench.methods.param_types import bounds_text, field_hints

_KEY = "homebench"

Status = Literal["", "departure", "reading"]


@dataclass(frozen=True)
class ParamInfo:
    """What a parameter means; ``paper`` (departure) or ``reading`` (ambiguous text), if any."""

    meaning: str
    paper: str = ""
    reading: str = ""


@dataclass(frozen=True)
class ParameterDoc:
    """One parameter as listed: name, type and default as text, meaning, status and its note;
    the bounds its type sets (">= 0", "" for none), the default itself (``value``) and whether
    the parameter has none (``required``)."""

    name: str
    type: str
    default: str
    meaning: str = ""
    status: Status = ""
    note: str = ""
    bounds: str = ""
    value: Any = dataclasses.field(default=None, compare=False)
    required: bool = dataclasses.field(default=False, compare=False)


def param(default: Any, meaning: str, *, paper: str = "", reading: str = "") -> Any:
    """A dataclass field with a default and its documentation (see the module docstring)."""
    if paper and reading:
        raise ValueError("a parameter is either a departure (paper=) or a reading (reading=)")
    return dataclasses.field(
        default=default, metadata={_KEY: ParamInfo(meaning, paper=paper, reading=reading)}
    )


def same_as(owner: type, name: str, scope: str = "") -> Any:
    """A field with the default and documentation of ``owner``'s field ``name`` (a method that
    exposes another dataclass's parameters as its own); ``scope``, when given, says where the
    parameter applies, before its meaning (``"With scheme 'x' only."``)."""
    source = next(f for f in dataclasses.fields(owner) if f.name == name)
    metadata = source.metadata
    if scope:
        info = metadata[_KEY]
        metadata = {_KEY: dataclasses.replace(info, meaning=f"{scope} {info.meaning}")}
    return dataclasses.field(default=source.default, metadata=metadata)


def type_text(hint: Any) -> str:
    """Plain text of a type hint: ``one of a | b`` for Literals, ``int | None`` for unions,
    ``tuple[float, float]`` for generic types, ``int >= 0`` for a bounded one."""
    if isinstance(hint, str):  # an annotation that did not resolve: its text
        return hint.strip("'\"")
    origin, args = get_origin(hint), get_args(hint)
    if origin is Annotated:
        return " ".join(filter(None, [type_text(args[0]), bounds_text(hint)]))
    if origin is Literal:
        return "one of " + " | ".join(str(choice) for choice in args)
    if args and origin in (typing.Union, types.UnionType):
        return " | ".join("None" if a is type(None) else type_text(a) for a in args)
    return str(hint) if args else getattr(hint, "__name__", str(hint))


def _default(field: dataclasses.Field[Any]) -> Any:
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return dataclasses.MISSING


def parameter_docs(cls: type) -> list[ParameterDoc]:
    """The parameters (init fields) of a method dataclass, documented or not, in field order."""
    hints = field_hints(cls)
    docs = []
    for each in _init_fields(cls):
        info = each.metadata.get(_KEY, ParamInfo(""))
        default = _default(each)
        shown = "(required)" if default is dataclasses.MISSING else repr(default)
        hint = hints.get(each.name, each.type)
        status: Status = "departure" if info.paper else "reading" if info.reading else ""
        docs.append(
            ParameterDoc(
                each.name,
                type_text(hint),
                shown,
                info.meaning,
                status,
                info.paper or info.reading,
                bounds_text(hint) if not isinstance(hint, str) else "",
                None if default is dataclasses.MISSING else default,
                default is dataclasses.MISSING,
            )
        )
    return docs


#: Width of the wrapped text of ``homebench methods`` and of the generated docstrings.
WIDTH = 100


def _annotation(doc: ParameterDoc) -> str:
    if doc.status == "departure":
        return f"[departure, opt-in. Paper: {doc.note}]"
    if doc.status == "reading":
        return f"[reading: {doc.note}]"
    return ""


def parameter_lines(docs: Sequence[ParameterDoc], indent: str = "    ") -> list[str]:
    """``name = default (type)`` per parameter, then its meaning and annotation, indented and
    wrapped."""
    lines = []
    for doc in docs:
        lines.append(f"{indent}{doc.name} = {doc.default} ({doc.type})")
        for text in (doc.meaning, _annotation(doc)):
            lines.extend(
                textwrap.wrap(
                    text, WIDTH, initial_indent=indent * 2, subsequent_indent=indent * 2 + " "
                )
            )
    return lines


def paper_statement(cls: type, params: dict[str, Any]) -> str:
    """How a method entry with ``params`` stands to its paper, in one sentence: "the paper's
    defaults", or which parameters differ from them and which departures are switched on.

    ``params`` may hold every parameter (a resolved config) or only the given ones.
    """
    changed, departures = [], []
    for doc, field in zip(parameter_docs(cls), _init_fields(cls), strict=True):
        if field.name not in params:
            continue
        default = _default(field)
        value = params[field.name]
        if default is dataclasses.MISSING or _same_value(value, default):
            continue
        if doc.status == "departure":
            departures.append(f"{field.name} = {value!r}")
        else:
            changed.append(f"{field.name} = {value!r} (default {default!r})")
    if not changed and not departures:
        return "the paper's defaults"
    parts = []
    if changed:
        parts.append("changed: " + ", ".join(changed))
    if departures:
        parts.append("departures from the paper switched on: " + ", ".join(departures))
    return "the paper's defaults except " + "; ".join(parts)


def _init_fields(cls: type) -> list[dataclasses.Field[Any]]:
    return [f for f in dataclasses.fields(cls) if f.init]


def _same_value(a: Any, b: Any) -> bool:
    """Equal as a config would hold them (a tuple default equals a YAML list)."""
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return list(a) == list(b)
    return bool(a == b)


def first_paragraph(doc: str | None) -> str:
    """The first paragraph of a docstring, on one line, reStructuredText roles and literals as
    plain text."""
    text = " ".join((doc or "").strip().split("\n\n")[0].split())
    return re.sub(r"(?::\w+:)?`+([^`]+)`+", r"\1", text)


def summary(cls: type) -> str:
    """The first paragraph of a class docstring (:func:`first_paragraph`)."""
    return first_paragraph(cls.__doc__)


def documented(cls: type) -> type:
    """Class decorator: append the parameter list (from the fields' metadata) to ``__doc__``."""
    cls.__doc__ = f"{(cls.__doc__ or '').rstrip()}\n\nParameters:\n\n" + "\n".join(
        parameter_lines(parameter_docs(cls))
    )
    return cls
