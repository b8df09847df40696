"""The code version of a method: what distribution it comes from and a hash of its source.

A method's results change when its code changes, so job and feature keys hold its code version:
the distribution and version that provide it (``homebench 0.1.0`` for the built-ins, the
plugin's for a plugin) and a sha256 of the source of the method's module and of every module of
the same top-level package it imports, transitively. Imports are found by parsing the source
(:mod:`ast`), never by importing it; imports inside functions count too. Importing ``a.b.c``
does not take in the ``__init__`` of ``a`` or ``a.b`` (their code runs, but rarely decides a
result, and a package ``__init__`` that imports every method would tie all methods together);
``from a.b import name`` takes in ``a.b`` when ``name`` is not a module itself.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
from collections.abc import Iterator
from pathlib import Path

from homebench.methods import registry


def _locations(top: str) -> tuple[Path | None, list[Path]]:
    """The file of a top-level module and, for a package, its folders (found, not imported)."""
    spec = importlib.util.find_spec(top)
    if spec is None:
        raise ModuleNotFoundError(f"no module named {top!r}")
    folders = [Path(p) for p in spec.submodule_search_locations or []]
    return (Path(spec.origin) if spec.has_location and spec.origin else None), folders


def _module_file(name: str) -> Path | None:
    """The source file of module ``name`` (a package's ``__init__.py``), or None."""
    top, *parts = name.split(".")
    origin, folders = _locations(top)
    if not parts:
        return origin if origin is not None and origin.suffix == ".py" else None
    for folder in folders:
        base = folder.joinpath(*parts)
        for candidate in (base / "__init__.py", base.with_suffix(".py")):
            if candidate.is_file():
                return candidate
    return None


def _imports(name: str, path: Path) -> set[str]:
    """Module names the source of module ``name`` (at ``path``) imports, anywhere in it."""
    tree = ast.parse(path.read_bytes(), filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top = name.partition(".")[0]
    found: set[str] = set()
    for node in _statements(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            parts = package.split(".")
            parent = parts[: len(parts) - node.level + 1] if node.level else []
            base = ".".join([*parent, *([node.module] if node.module else [])])
            if base.partition(".")[0] != top:  # another package: never looked up (it may
                found.add(base)  # be an optional one that is not installed)
                continue
            submodules = {f"{base}.{alias.name}" for alias in node.names}
            modules = {m for m in submodules if _module_file(m) is not None}
            found.update(modules)
            if modules != submodules:
                found.add(base)
    return found


def _statements(tree: ast.Module) -> Iterator[ast.stmt]:
    """Every statement of a module, at any depth (in functions, classes, branches, handlers,
    cases). Imports are statements, so the expressions, most of a module's nodes, are never
    visited: a seventh of the time of :func:`ast.walk` (homebench: 15,119 of 198,477 nodes)."""
    todo: list[ast.AST] = [tree]
    while todo:
        node = todo.pop()
        if isinstance(node, ast.stmt):
            yield node
        for _, value in ast.iter_fields(node):
            if isinstance(value, list) and value and isinstance(value[0], _BLOCK_ITEMS):
                todo.extend(value)


#: What the lists of statements and of their blocks hold (bodies, ``except`` handlers, cases).
_BLOCK_ITEMS = (ast.stmt, ast.excepthandler, ast.match_case)


def source_closure(module: str) -> dict[str, Path]:
    """``module`` and the modules of its top-level package it imports, transitively: their
    source files by module name."""
    top = module.partition(".")[0]
    closure: dict[str, Path] = {}
    todo = [module]
    while todo:
        name = todo.pop()
        path = _module_file(name)
        if name in closure or path is None:
            continue
        closure[name] = path
        todo.extend(m for m in _imports(name, path) if m.partition(".")[0] == top)
    return closure


def module_version(module: str) -> str:
    """A sha256 (16 hex digits) of the source of ``module`` and of the modules of its
    top-level package it imports, transitively."""
    digest = hashlib.sha256()
    for name, path in sorted(source_closure(module).items()):
        source = path.read_bytes()
        digest.update(f"{name}\0{len(source)}\0".encode() + source)
    return digest.hexdigest()[:16]


def code_version(cls: type) -> str:
    """``"<distribution> <version> <source hash>"`` of a method class (``local`` instead of
    distribution and version for a class no installed distribution provides)."""
    origin = registry.distribution(cls)
    prefix = f"{origin[0]} {origin[1]}" if origin is not None else "local"
    return f"{prefix} {module_version(cls.__module__)}"
