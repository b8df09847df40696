"""The method registry: names -> method classes, built-ins and entry points.

Third-party methods register through the entry-point group ``homebench.methods``; each entry
point names a class that satisfies :class:`homebench.methods.base.HomingMethod` and is a
dataclass whose fields are its parameters.
"""

from __future__ import annotations

import dataclasses
from importlib.metadata import entry_points
from typing import Any, TypeVar

from homebench.errors import ConfigError

T = TypeVar("T")

_REGISTRY: dict[str, type] = {}
_ENTRY_POINT_GROUP = "homebench.methods"


def register(cls: type[T]) -> type[T]:
    """Class decorator: register a method dataclass under its ``name``."""
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls.__name__} must be a dataclass (its fields are its parameters)")
    name = cls.name  # type: ignore[attr-defined]
    if name in _REGISTRY and _REGISTRY[name] is not cls:
        raise ValueError(f"method name {name!r} is registered twice")
    _REGISTRY[name] = cls
    return cls


def _load_all() -> None:
    import homebench.methods  # noqa: F401  (registers the built-ins)

    for ep in entry_points(group=_ENTRY_POINT_GROUP):
        register(ep.load())


def available() -> dict[str, type]:
    """All registered method classes by name, sorted by name."""
    _load_all()
    return dict(sorted(_REGISTRY.items()))


def parameters(name: str) -> dict[str, Any]:
    """Parameter names and defaults of a registered method."""
    cls = get(name)
    return {
        f.name: (f.default if f.default is not dataclasses.MISSING else f.default_factory())
        for f in dataclasses.fields(cls)
        if f.init
    }


def get(name: str) -> type:
    methods = available()
    if name not in methods:
        raise ConfigError(f"unknown method {name!r}; known: {', '.join(methods) or 'none'}")
    return methods[name]


def create(name: str, **params: Any) -> Any:
    """Instantiate a registered method; unknown parameters are a ConfigError."""
    cls = get(name)
    known = {f.name for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(params) - known)
    if unknown:
        raise ConfigError(
            f"method {name!r} has no parameter(s) {', '.join(unknown)}; "
            f"known: {', '.join(sorted(known))}"
        )
    return cls(**params)
