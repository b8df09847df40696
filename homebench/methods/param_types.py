"""The types of method parameters: every value a method is given is checked against its field's
type hint, by pydantic in strict mode, before the method is made.

Strict means: an integer where an integer is expected (not ``2.5``, ``"3"`` or ``true``), a
number where a float is expected (an integer is one), ``true`` or ``false`` for a bool, one of
the choices of a ``Literal``; a tuple field also takes a list (YAML has no tuples). A field
bounds its values as pydantic's fields do: ``seed: Annotated[int, Field(ge=0)]`` (or
``annotated_types``' ``Ge(0)``). Floats must
be finite: ``nan`` and ``inf`` are refused unless the field opts out with pydantic's marker,
``Annotated[float, AllowInfNan()]`` (no built-in method does: where "no limit" or "off" is
meant, they take ``None``). A field without a hint, or with one that does not resolve or that
pydantic cannot check (a class of the plugin's own), takes any value.

The values are checked, not converted: the method gets them as given.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import operator
import reprlib
import sys
import types
import typing
from collections.abc import Mapping
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import AllowInfNan, ConfigDict, Strict, TypeAdapter, ValidationError

from homebench.errors import ConfigError

_STRICT = ConfigDict(strict=True, allow_inf_nan=False)
_UNIONS = (Union, types.UnionType)
#: Singular and plural names of the scalar types, for messages.
_NAMES = {
    int: ("an integer", "integers"),
    float: ("a finite number", "finite numbers"),
    bool: ("true or false", "booleans"),
    str: ("a string", "strings"),
    type(None): ("null", "nulls"),
}
#: The bounds a field's ``Annotated`` markers may set: their attribute and its sign.
_BOUNDS = (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<"))


def field_hints(cls: type) -> dict[str, Any]:
    """The type hints of a dataclass's fields (``Annotated`` kept); a hint that does not
    resolve (a plugin's annotation naming what its module does not import) stays its text,
    and does not keep the other fields' from resolving."""
    try:
        return typing.get_type_hints(cls, include_extras=True)
    except Exception:  # any error of any annotation: resolve them one by one
        return {field.name: _resolve(cls, field.name, field.type) for field in _fields(cls)}


def _resolve(cls: type, name: str, annotation: Any) -> Any:
    """One annotation resolved in the module and class that declare it, or its text."""
    if not isinstance(annotation, str):
        return annotation
    owner = next((base for base in cls.__mro__ if name in inspect.get_annotations(base)), cls)
    module = vars(sys.modules[owner.__module__]) if owner.__module__ in sys.modules else {}
    holder = types.SimpleNamespace(__annotations__={name: annotation})
    try:
        return typing.get_type_hints(holder, module, dict(vars(owner)), include_extras=True)[name]
    except Exception:  # a name its module does not hold, a syntax error: keep the text
        return annotation


def _fields(cls: type) -> list[dataclasses.Field[Any]]:
    return [field for field in dataclasses.fields(cls) if field.init]


def parameter_problem(cls: type, name: str, value: Any) -> str:
    """Why ``value`` cannot be parameter ``name`` of method class ``cls`` ("expected an integer,
    got 2.5"); "" when it can, or when ``cls`` has no such parameter or nothing to check."""
    checker = _checkers(cls).get(name)
    if checker is None:
        return ""
    hint, adapter = checker
    try:
        adapter.validate_python(value)
    except ValidationError:
        return f"expected {expected(hint)}, got {reprlib.repr(value)}"
    return ""


def check_parameters(cls: type, params: Mapping[str, Any], prefix: str) -> None:
    """ConfigError ``"<prefix><name>: <problem>"`` for the first of ``params`` whose value its
    field's type refuses (:func:`parameter_problem`)."""
    for name, value in params.items():
        problem = parameter_problem(cls, name, value)
        if problem:
            raise ConfigError(f"{prefix}{name}: {problem}")


def check_fields(method: Any) -> None:
    """:func:`check_parameters` on the fields of a method instance (or of another dataclass of
    parameters), from its ``__post_init__``; the error names the method (or the class)."""
    values = {field.name: getattr(method, field.name) for field in _fields(type(method))}
    name = getattr(method, "name", type(method).__name__)
    check_parameters(type(method), values, prefix=f"{name}: ")


@functools.cache
def _checkers(cls: type) -> dict[str, tuple[Any, TypeAdapter[Any]]]:
    """(hint, validator) of every parameter of ``cls`` that has a checkable hint."""
    hints = field_hints(cls)
    checkers = {}
    for field in _fields(cls):
        hint = hints.get(field.name, field.type)
        if isinstance(hint, str):
            continue
        try:
            checkers[field.name] = (hint, TypeAdapter(_lists_for_tuples(hint), config=_STRICT))
        except Exception:  # a type pydantic cannot check (a class of the method's own)
            continue
    return checkers


def _lists_for_tuples(hint: Any) -> Any:
    """``hint`` with every tuple in it taking a list as well (and nothing else more)."""
    origin, args = get_origin(hint), get_args(hint)
    if origin is Annotated:
        return Annotated[(_lists_for_tuples(args[0]), *hint.__metadata__)]
    if origin in _UNIONS:
        return functools.reduce(operator.or_, map(_lists_for_tuples, args))
    if origin in (list, dict):
        return origin[tuple(_lists_for_tuples(arg) for arg in args)]
    if hint is tuple or origin is tuple:
        inner = tuple[tuple(_lists_for_tuples(arg) for arg in args)] if args else tuple
        return Annotated[inner, Strict(False)]
    return hint


def expected(hint: Any) -> str:
    """What a value of type ``hint`` is, in words: "an integer", "one of ssd, dot", "a list of
    2 finite numbers or null"."""
    origin, args = get_origin(hint), get_args(hint)
    if origin is Annotated:
        inf_nan = any(isinstance(m, AllowInfNan) and m.allow_inf_nan for m in hint.__metadata__)
        kind = "a number" if inf_nan and args[0] is float else expected(args[0])
        return " ".join(filter(None, [kind, bounds_text(hint)]))
    if origin is Literal:
        return "one of " + ", ".join(map(str, args))
    if origin in _UNIONS:
        return " or ".join(expected(arg) for arg in args)
    if hint in _NAMES:
        return _NAMES[hint][0]
    if hint in (tuple, list) or origin in (tuple, list):
        return _sequence(args)
    return getattr(hint, "__name__", str(hint))


def bounds_text(hint: Any) -> str:
    """The bounds an ``Annotated`` hint's markers set (``annotated_types``' ``Ge(0)``, or
    pydantic's ``Field(ge=0)``, which holds such markers), in words: ">= 0", "> 0 <= 1"; ""
    for none."""
    markers = get_args(hint)[1:] if get_origin(hint) is Annotated else ()
    markers = tuple(m for marker in markers for m in (marker, *getattr(marker, "metadata", ())))
    return " ".join(
        f"{sign} {getattr(marker, name)}"
        for marker in markers
        for name, sign in _BOUNDS
        if getattr(marker, name, None) is not None
    )


def _sequence(args: tuple[Any, ...]) -> str:
    """A list whose items have the types ``args`` (a tuple's or a list's), in words."""
    items = args[:-1] if args[-1:] == (Ellipsis,) else args
    kinds = set(items)
    if len(kinds) != 1 or next(iter(kinds)) not in _NAMES:
        return "a list"
    count = f"{len(items)} " if len(args) == len(items) and len(args) > 1 else ""
    return f"a list of {count}{_NAMES[next(iter(kinds))][1]}"
