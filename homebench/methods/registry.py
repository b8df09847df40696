"""The method registry: names -> method classes, built-ins and plugins.

Built-in methods register with :func:`register` when :mod:`homebench.methods` is imported.
Third-party methods register through the entry-point group ``homebench.methods``: each entry
point's name is the method's name and its value a class that satisfies
:class:`homebench.methods.base.HomingMethod` and is a dataclass whose fields are its parameters.

Plugins load lazily: entry points are listed by name, and a plugin is imported only when a
config or command needs that name, so a broken plugin breaks only what uses it (with one line
naming its distribution). A plugin whose features hold dataclasses of its own registers those
classes with :func:`register_features` (feature files rebuild only registered classes).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import importlib
import importlib.metadata
from importlib.metadata import (
    EntryPoint,
    PackageNotFoundError,
    entry_points,
    packages_distributions,
    version,
)
from typing import Any, TypeVar

from homebench.errors import ConfigError, HomebenchError
from homebench.methods.param_types import check_parameters
from homebench.methods.threads import limit_calls
from homebench.suggest import did_you_mean, unknown

T = TypeVar("T")

_REGISTRY: dict[str, type] = {}
_FEATURES: dict[str, type] = {}
_BROKEN: dict[str, str] = {}
_PLUGINS: dict[type, tuple[str, str]] = {}  # class -> (distribution, version) of its plugin
_ENTRY_POINT_GROUP = "homebench.methods"


class PluginError(HomebenchError):
    """An installed plugin that cannot be loaded, named with its distribution."""


def register(cls: type[T]) -> type[T]:
    """Class decorator: register a method dataclass under its ``name``; its calls then run with
    one BLAS / OpenMP thread in any process (:mod:`~homebench.methods.threads`)."""
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls.__name__} must be a dataclass (its fields are its parameters)")
    name = cls.name  # type: ignore[attr-defined]
    if name in _REGISTRY and _REGISTRY[name] is not cls:
        raise ValueError(f"method name {name!r} is registered twice")
    limit_calls(cls)
    _REGISTRY[name] = cls
    return cls


def register_features(cls: type[T]) -> type[T]:
    """Class decorator: allow a dataclass in feature files (a plugin's own feature types)."""
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls.__name__} must be a dataclass to be stored in feature files")
    _FEATURES[f"{cls.__module__}:{cls.__qualname__}"] = cls
    return cls


def feature_classes() -> tuple[type, ...]:
    """The dataclasses plugins registered for feature files."""
    return tuple(_FEATURES.values())


def _builtins() -> dict[str, type]:
    # imported by name, not by an import statement: a method's code version follows its
    # module's imports, which must not take in every other method through this module
    importlib.import_module("homebench.methods")
    return _REGISTRY


def _entry_points() -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=_ENTRY_POINT_GROUP)}


def _origin(ep: EntryPoint) -> tuple[str, str]:
    dist = ep.dist
    return (dist.name, dist.version) if dist is not None else (ep.value, "unknown version")


def _load(ep: EntryPoint) -> type:
    """Import a plugin's class and register it; PluginError (one line) if that fails."""
    dist, dist_version = _origin(ep)
    try:
        cls = ep.load()
        name = getattr(cls, "name", None)
        if name != ep.name:
            raise TypeError(f"the entry point names a method called {name!r}, not {ep.name!r}")
        register(cls)
    except Exception as error:  # a plugin may fail in any way; name it, not its traceback
        detail = (str(error).strip().splitlines() or [""])[0]
        _BROKEN[ep.name] = (
            f"method {ep.name!r} comes from distribution {dist} {dist_version}, which is "
            f"broken: {type(error).__name__}: {detail}"
        )
        raise PluginError(_BROKEN[ep.name]) from None
    _PLUGINS[cls] = (dist, dist_version)
    return cls


def names() -> list[str]:
    """Every method name, built-in or plugin, without importing any plugin."""
    return sorted({*_builtins(), *_entry_points()})


def available() -> dict[str, type]:
    """Every method class that loads, by name (plugins imported now; see :func:`broken`)."""
    registered = _builtins()
    for name, ep in _entry_points().items():
        if name not in registered:
            with contextlib.suppress(PluginError):  # remembered in broken()
                _load(ep)
    return dict(sorted(registered.items()))


def broken() -> dict[str, str]:
    """Plugins that failed to load so far, by method name: the one-line reason."""
    return dict(sorted(_BROKEN.items()))


def get(name: str) -> type:
    """The class of method ``name``, importing its plugin if need be."""
    registered = _builtins()
    if name in registered:
        return registered[name]
    ep = _entry_points().get(name)
    if ep is None:
        raise ConfigError(unknown("method", name, names()))
    return _load(ep)


def distribution(cls: type) -> tuple[str, str] | None:
    """(distribution, version) that provides a method class, or None when it comes from no
    installed distribution (a script, a test module)."""
    if cls in _PLUGINS:
        return _PLUGINS[cls]
    top = cls.__module__.partition(".")[0]
    name = _declaring(top) or next(iter(_distributions().get(top, ())), None)
    return (name, version(name)) if name else None


@functools.cache
def _declaring(top: str) -> str | None:
    """The distribution named ``top``, if it declares the top-level module ``top`` (as
    homebench's own does): found without reading the metadata of every installed
    distribution, which took a run's main process a tenth of a second."""
    try:
        dist = importlib.metadata.distribution(top)
    except PackageNotFoundError:
        return None
    return dist.metadata["Name"] if top in (dist.read_text("top_level.txt") or "").split() else None


@functools.cache
def _distributions() -> dict[str, list[str]]:
    return packages_distributions()


def parameters(name: str) -> dict[str, Any]:
    """Parameter names and defaults of a registered method."""
    cls = get(name)
    return {
        f.name: (f.default if f.default is not dataclasses.MISSING else f.default_factory())
        for f in dataclasses.fields(cls)
        if f.init
    }


def create(name: str, **params: Any) -> Any:
    """Instantiate a registered method; unknown parameters, and values their field's type
    refuses (:mod:`~homebench.methods.param_types`), are a ConfigError naming the parameter
    (and for an unknown one the closest known one, or them all)."""
    cls = get(name)
    known = {f.name for f in dataclasses.fields(cls) if f.init}
    extra = sorted(set(params) - known)
    if extra:
        hints = [f"{p}{did_you_mean(p, known)}" for p in extra]
        listed = (
            ""
            if any(h != p for h, p in zip(hints, extra, strict=True))
            else (f"; known: {', '.join(sorted(known))}")
        )
        raise ConfigError(f"method {name!r} has no parameter(s) {', '.join(hints)}{listed}")
    check_parameters(cls, params, prefix=f"method {name!r}: ")
    return cls(**params)
