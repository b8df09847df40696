"""YAML files in, validated pydantic models out, with errors naming the file, line and key path.

The one loader of every YAML file homebench reads (run configs, manifests): syntax errors give
line and column, duplicate keys are errors (PyYAML would silently keep the last), and each
validation problem is reported as ``file:line: key.path: message``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from homebench.errors import ConfigError

M = TypeVar("M", bound=BaseModel)


def _read(path: Path, what: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such {what}") from None
    except OSError as error:
        raise ConfigError(f"{path}: cannot read the {what} ({error.strerror or error})") from None
    except UnicodeDecodeError as error:
        raise ConfigError(f"{path}: the {what} is not UTF-8 text ({error})") from None


def load_model(model: type[M], path: Path, what: str = "file") -> M:
    """Read a YAML file and validate it against ``model`` (``what`` names it in errors)."""
    return parse_model(model, _read(path, what), str(path), what)


def load_yaml_mapping(path: Path, what: str = "file") -> dict[str, Any]:
    """Read a YAML file that must hold a mapping (not validated against a model)."""
    return _parse_mapping(_read(path, what), str(path), what)[0]


def _parse_mapping(text: str, origin: str, what: str) -> tuple[dict[str, Any], yaml.Node]:
    """The YAML mapping in ``text`` and its node (for line numbers); ConfigError otherwise."""
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            raise ConfigError(f"{origin}: the {what} is empty")
        _check_duplicate_keys(node, origin)
        data = loader.construct_document(node)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{origin}:{mark.line + 1}:{mark.column + 1}" if mark else origin
        raise ConfigError(f"{where}: YAML syntax error: {error.problem or error}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{origin}: YAML error: {error}") from None
    finally:
        loader.dispose()
    if not isinstance(data, dict):
        raise ConfigError(f"{origin}: a {what} is a mapping of keys, got {type(data).__name__}")
    return data, node


def parse_model(model: type[M], text: str, origin: str, what: str = "file") -> M:
    """Validate YAML ``text`` against ``model``; ``origin`` (a file name) starts every error."""
    data, node = _parse_mapping(text, origin, what)
    try:
        return model.model_validate(data)
    except ValidationError as error:
        lines = [_describe(e, node, origin) for e in error.errors()]
        raise ConfigError("\n".join(lines)) from None


def _check_duplicate_keys(node: yaml.Node, origin: str) -> None:
    """PyYAML silently keeps the last of two equal keys; a manifest treats that as an error."""
    if isinstance(node, yaml.MappingNode):
        seen: set[str] = set()
        for key, value in node.value:
            if key.value in seen:
                where = f"{origin}:{key.start_mark.line + 1}:{key.start_mark.column + 1}"
                raise ConfigError(f"{where}: duplicate key {key.value!r}")
            seen.add(key.value)
            _check_duplicate_keys(value, origin)
    elif isinstance(node, yaml.SequenceNode):
        for item in node.value:
            _check_duplicate_keys(item, origin)


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
