"""YAML files in, validated pydantic models out, with errors that name the file and key path."""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from homebench.errors import ConfigError

M = TypeVar("M", bound=BaseModel)


def load_yaml_file(path: Path) -> Any:
    """Parse a YAML file; a missing file or a syntax error is a ConfigError with line and column."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ConfigError(f"{path}: cannot be read ({error})") from None
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        raise ConfigError(f"{path}: YAML syntax error at {where}{error.problem}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{path}: YAML error: {error}") from None


def validation_message(source: Path | str, error: ValidationError) -> str:
    """One line per problem: ``source: key.path: message`` (first five problems)."""
    lines = []
    for problem in error.errors()[:5]:
        where = ".".join(str(part) for part in problem["loc"]) or "(top level)"
        lines.append(f"{source}: {where}: {problem['msg']}")
    more = len(error.errors()) - 5
    if more > 0:
        lines.append(f"{source}: ... and {more} more problem(s)")
    return "\n".join(lines)


def validate(model: type[M], data: Any, source: Path | str) -> M:
    """Validate ``data`` against ``model``; errors become one ConfigError naming source and keys."""
    if data is None:
        raise ConfigError(f"{source}: the file is empty")
    try:
        return model.model_validate(data)
    except ValidationError as error:
        raise ConfigError(validation_message(source, error)) from None


def load_model(model: type[M], path: Path) -> M:
    """Load and validate a YAML file in one step."""
    return validate(model, load_yaml_file(path), path)
