"""YAML files in, validated pydantic models out, with errors naming the file, line and key path.

The one loader of every YAML file homebench reads (run configs, route configs, manifests): syntax
errors give line and column, duplicate keys are errors (PyYAML would silently keep the last), and
each validation problem is reported as ``file:line: key.path: message``.

YAML is input from anyone (a shared config, a downloaded manifest), so reading it is bounded:
only regular files of at most MAX_YAML_BYTES are read (a FIFO or /dev/zero is refused before a
byte is read), nesting stops at MAX_YAML_DEPTH, and a document may hold at most MAX_YAML_NODES
nodes once its aliases are expanded (an "alias bomb" of nested anchors is refused after one
pass over its distinct nodes). Every failure is a ConfigError of one line.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError
from yaml.composer import Composer
from yaml.constructor import SafeConstructor
from yaml.resolver import Resolver

from homebench.errors import ConfigError
from homebench.fileio import read_small_text, size_text

try:  # libyaml scans and parses about 50 times faster than PyYAML's own Python code
    from yaml.cyaml import CParser as _EventParser
except ImportError:  # a PyYAML built without libyaml: the same events, slower
    from yaml.parser import Parser
    from yaml.reader import Reader
    from yaml.scanner import Scanner

    class _EventParser(Reader, Scanner, Parser):  # type: ignore[no-redef]
        def __init__(self, text: str):
            Reader.__init__(self, text)
            Scanner.__init__(self)
            Parser.__init__(self)


M = TypeVar("M", bound=BaseModel)

#: Largest YAML file read. Shipped configs are ~2 KB and manifests ~30 KB; a manifest with the
#: sha256 of 20,000 images is ~1.7 MB. Parsing 4 MiB takes a few seconds at most.
MAX_YAML_BYTES = 4 << 20
#: Deepest nesting of mappings and lists (configs and manifests nest about 6 deep).
MAX_YAML_DEPTH = 64
#: Most nodes of a document, counted with its aliases expanded (a 4 MiB manifest of sums holds
#: ~110,000): the work of every later step (validation, the checks below) is bounded by it.
MAX_YAML_NODES = 200_000
#: Most validation errors listed; the others are counted in one last line.
MAX_REPORTED_ERRORS = 20


def _read(path: Path, what: str) -> str:
    """The text of a regular file of at most MAX_YAML_BYTES; ConfigError otherwise
    (:func:`homebench.fileio.read_small_text`)."""
    return read_small_text(path, MAX_YAML_BYTES, what, ConfigError)


@dataclass(frozen=True)
class YamlDocument:
    """A YAML mapping as read once: its data with the overrides applied, its node graph (the
    line of each key, for errors) and its origin (the file name every error starts with)."""

    data: dict[str, Any]
    node: yaml.Node
    origin: str

    def overridden(self, overrides: Sequence[str]) -> YamlDocument:
        """This document with more ``key.path=value`` ``overrides`` applied."""
        return YamlDocument(
            apply_overrides(self.data, overrides, self.origin), self.node, self.origin
        )


def read_yaml(path: Path, what: str = "file", overrides: Sequence[str] = ()) -> YamlDocument:
    """Read a YAML file that must hold a mapping, with ``overrides`` applied (see
    :func:`apply_overrides`); not yet validated (:func:`validate`)."""
    return parse_yaml(_read(path, what), str(path), what, overrides)


def parse_yaml(
    text: str, origin: str, what: str = "file", overrides: Sequence[str] = ()
) -> YamlDocument:
    """The YAML mapping in ``text`` with ``overrides`` applied; ``origin`` starts every error."""
    data, node = _parse_mapping(text, origin, what)
    return YamlDocument(apply_overrides(data, overrides, origin), node, origin)


def load_model(model: type[M], path: Path, what: str = "file", overrides: Sequence[str] = ()) -> M:
    """Read a YAML file, apply ``overrides`` and validate it against ``model`` (``what`` names
    it in errors)."""
    return validate(model, read_yaml(path, what, overrides))


def apply_overrides(data: dict[str, Any], overrides: Sequence[str], origin: str) -> dict[str, Any]:
    """``data`` with each ``key.path=value`` of ``overrides`` set (a new mapping; ``data`` is
    not changed). The key path names mapping keys and list indices (``methods.0.params.ratio``);
    missing mapping keys are created; the value is YAML (``0.7``, ``all``, ``[1, 2]``), read
    with the same limits as a file. ConfigError naming the override when it cannot be set."""
    data = copy.deepcopy(data)
    for override in overrides:
        key, sep, text = override.partition("=")
        parts = key.strip().split(".")
        if not sep or not all(parts):
            raise ConfigError(f"override {override!r}: expected key.path=value")
        try:
            _, value = _load(text, f"override {key}", "value")
        except yaml.YAMLError as error:
            raise ConfigError(f"override {override!r}: {_one_line(error)}") from None
        node: Any = data
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            where = ".".join(parts[: depth + 1])
            if isinstance(node, dict):
                if last:
                    node[part] = value
                else:
                    node = node.setdefault(part, {})
            elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
                if last:
                    node[int(part)] = value
                else:
                    node = node[int(part)]
            else:
                raise ConfigError(
                    f"{origin}: override {override!r}: {where} is not a key or index of the config"
                )
    return data


def _parse_mapping(text: str, origin: str, what: str) -> tuple[dict[str, Any], yaml.Node]:
    """The YAML mapping in ``text`` and its node (for line numbers); ConfigError otherwise."""
    if len(text) > MAX_YAML_BYTES:
        raise ConfigError(
            f"{origin}: the {what} is larger than the {size_text(MAX_YAML_BYTES)} limit"
        )
    try:
        node, data = _load(text, origin, what)
    except yaml.MarkedYAMLError as error:
        where = _where(origin, error.problem_mark or error.context_mark)
        problem = _one_line(error.problem or error.context or error)
        if "maximum nesting depth" in problem:  # PyYAML 6.0.4's parser stops it first
            raise ConfigError(f"{where}: YAML nested deeper than {MAX_YAML_DEPTH} levels") from None
        raise ConfigError(f"{where}: YAML syntax error: {problem}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{origin}: YAML error: {_one_line(error)}") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{origin}: a {what} is a mapping of keys, got {type(data).__name__}")
    return data, node


def _load(text: str, origin: str, what: str) -> tuple[yaml.Node, Any]:
    """The checked node graph of ``text`` and the Python data it constructs."""
    loader = _Loader(text, origin)
    try:
        node = loader.get_single_node()
        if node is None:
            raise ConfigError(f"{origin}: the {what} is empty")
        _check_graph(node, origin)
        return node, loader.construct_document(node)
    finally:
        loader.dispose()


def _one_line(message: object) -> str:
    return " ".join(str(message).split())


def _where(origin: str, mark: yaml.Mark | None) -> str:
    """``file:line:column`` of a mark (1-based), or the file alone."""
    return f"{origin}:{mark.line + 1}:{mark.column + 1}" if mark else origin


class _Loader(Composer, SafeConstructor, Resolver, _EventParser):
    """A safe loader (PyYAML's Python composer on libyaml's events) that stops at MAX_YAML_DEPTH
    levels and MAX_YAML_NODES nodes while it composes, and reports values it cannot read (a
    5000-digit integer, the 45th of a month) at their line."""

    def __init__(self, text: str, origin: str):
        _EventParser.__init__(self, text)
        Composer.__init__(self)
        SafeConstructor.__init__(self)
        Resolver.__init__(self)
        self.origin = origin
        self.depth = 0
        self.n_nodes = 0

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        self.depth += 1
        self.n_nodes += 1
        try:
            if self.depth > MAX_YAML_DEPTH:
                where = _where(self.origin, self.peek_event().start_mark)
                raise ConfigError(f"{where}: YAML nested deeper than {MAX_YAML_DEPTH} levels")
            if self.n_nodes > MAX_YAML_NODES:
                where = _where(self.origin, self.peek_event().start_mark)
                raise ConfigError(f"{where}: YAML with more than {MAX_YAML_NODES:,} nodes")
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep)
        except (ValueError, OverflowError) as error:
            where = _where(self.origin, node.start_mark)
            raise ConfigError(f"{where}: cannot read the value ({_one_line(error)})") from None


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _check_graph(root: yaml.Node, origin: str) -> None:
    """Check the composed document, visiting each node once (aliased nodes are shared).

    Mapping keys must be plain values and unique (PyYAML would silently keep the last of two
    equal keys); no alias may refer to a node it is inside of; expanded, the document must have
    at most MAX_YAML_NODES nodes and MAX_YAML_DEPTH levels. Iterative: no recursion limit.
    """
    size: dict[int, int] = {}  # id -> nodes of the expanded subtree (finished nodes)
    depth: dict[int, int] = {}
    open_nodes: set[int] = set()  # started, not finished: the current path from the root
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, finished = stack.pop()
        key = id(node)
        if finished:
            children = _children(node)
            open_nodes.discard(key)
            size[key] = 1 + sum(size[id(c)] for c in children)
            depth[key] = 1 + max((depth[id(c)] for c in children), default=0)
            if size[key] > MAX_YAML_NODES:
                raise ConfigError(
                    f"{_where(origin, node.start_mark)}: the YAML expands to more than "
                    f"{MAX_YAML_NODES:,} nodes through its aliases"
                )
            if depth[key] > MAX_YAML_DEPTH:
                raise ConfigError(
                    f"{_where(origin, node.start_mark)}: YAML nested deeper than "
                    f"{MAX_YAML_DEPTH} levels (through its aliases)"
                )
        elif key in open_nodes:
            raise ConfigError(f"{_where(origin, node.start_mark)}: a recursive alias")
        elif key not in size:
            if isinstance(node, yaml.MappingNode):
                _check_keys(node, origin)
            open_nodes.add(key)
            stack.append((node, True))
            stack.extend((c, False) for c in _children(node))


def _check_keys(node: yaml.MappingNode, origin: str) -> None:
    """The keys of a mapping are plain values (not lists or mappings), each given once."""
    seen: set[str] = set()
    for key, _ in node.value:
        where = _where(origin, key.start_mark)
        if not isinstance(key, yaml.ScalarNode):
            raise ConfigError(f"{where}: a key must be a plain value, not a list or mapping")
        if key.value in seen:
            raise ConfigError(f"{where}: duplicate key {key.value!r}")
        seen.add(key.value)


def parse_model(
    model: type[M], text: str, origin: str, what: str = "file", overrides: Sequence[str] = ()
) -> M:
    """Validate YAML ``text`` (with ``overrides`` applied) against ``model``; ``origin`` (a
    file name) starts every error."""
    return validate(model, parse_yaml(text, origin, what, overrides))


def validate(model: type[M], document: YamlDocument) -> M:
    """``document`` validated against ``model``; a ConfigError listing each problem as
    ``file:line: key.path: message``."""
    try:
        return model.model_validate(document.data)
    except ValidationError as error:
        errors = error.errors()
        origin = document.origin
        lines = [_describe(e, document.node, origin) for e in errors[:MAX_REPORTED_ERRORS]]
        if len(errors) > MAX_REPORTED_ERRORS:
            lines.append(f"{origin}: and {len(errors) - MAX_REPORTED_ERRORS} more problems")
        raise ConfigError("\n".join(lines)) from None


def _describe(error: dict[str, Any], root: yaml.Node, origin: str) -> str:
    """One validation error as "file:line: key.path: message"."""
    loc = [p for p in error["loc"] if isinstance(p, int | str)]
    path = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc).lstrip(".")
    line = _line_of(root, loc)
    message = error["msg"].removeprefix("Value error, ")
    where = f"{origin}:{line}" if line else origin
    return f"{where}: {path}: {message}" if path else f"{where}: {message}"


def _line_of(node: yaml.Node, loc: list[int | str]) -> int | None:
    """1-based line of the deepest YAML node along the key path ``loc``."""
    line = node.start_mark.line + 1
    for part in loc:
        if isinstance(node, yaml.MappingNode):
            match = [(k, v) for k, v in node.value if k.value == str(part)]
            if not match:
                break
            key, node = match[0]
            line = key.start_mark.line + 1
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int):
            if part >= len(node.value):
                break
            node = node.value[part]
            line = node.start_mark.line + 1
        else:
            break
    return line
