"""A run folder as the report sees it: its config, environment and tables, read from disk alone."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from homebench.analysis.tables import RunTables
from homebench.config import MetricsConfig, ResolvedRunConfig, RunConfig, kind_of
from homebench.data.naming import database_label
from homebench.errors import DataError
from homebench.evaluation.results import build_tables
from homebench.fileio import parse_json, read_record_text
from homebench.report.environment_record import EnvironmentRecord

CONFIG_FILE = "config.resolved.json"
ENVIRONMENT_FILE = "environment.json"


@dataclass(frozen=True)
class RunInfo:
    """What every run folder holds: ``config`` and ``environment`` as written by the run."""

    run_dir: Path
    config: dict[str, Any]
    environment: dict[str, Any]

    @property
    def kind(self) -> str:
        """The experiment kind: "route", "closed-loop" (their ``kind``) or "grid"."""
        return kind_of(self.config)

    @property
    def name(self) -> str:
        return str(self.config.get("name", self.run_dir.name))

    @property
    def started(self) -> datetime:
        """When the run started (UTC), from environment.json; the report's fixed date."""
        text = self.environment.get("started")
        try:
            value = datetime.fromisoformat(text) if isinstance(text, str) else None
        except ValueError:
            value = None
        if value is None:
            raise DataError(f"{self.run_dir / ENVIRONMENT_FILE}: no valid 'started' date")
        return value if value.tzinfo else value.replace(tzinfo=UTC)


@dataclass(frozen=True)
class RunData(RunInfo):
    """Everything a grid report draws from: the run's ``settings`` (its resolved config,
    validated), metrics settings and tables."""

    settings: RunConfig
    tables: RunTables

    @property
    def metrics(self) -> MetricsConfig:
        return self.settings.metrics

    @property
    def conditions(self) -> list[str]:
        """Conditions with results, in the config's order."""
        present = set(self.tables.pairs["condition"]) if not self.tables.pairs.empty else set()
        return [c for c in self.config.get("conditions", []) if c in present]

    def database_label(self, alias: str) -> str:
        """The database behind ``alias`` as the data commands name it
        (:func:`~homebench.data.naming.database_label`: its manifest's name, and the path the
        config gave), or its generated world; runs written before the environment recorded
        the manifest's name show the config's reference."""
        ref = self.config.get("databases", {}).get(alias)
        if not isinstance(ref, dict):
            return alias
        if ref.get("world"):
            world = ref["world"]
            return f"world {world.get('variant', 'original')} (seed {world.get('seed', 0)})"
        recorded = self.environment.get("databases", {}).get(alias)
        if isinstance(recorded, dict) and isinstance(recorded.get("name"), str):
            return database_label(recorded["name"], str(ref.get("name")))
        return str(ref.get("name"))

    def condition_title(self, condition: str) -> str:
        """``condition`` with the databases it pairs: "a-b (current: x, goal: y)"."""
        current, goal = condition.split("-", 1)
        return (
            f"{condition} (current: {self.database_label(current)}, "
            f"goal: {self.database_label(goal)})"
        )


def _read_json(path: Path) -> dict[str, Any]:
    """The JSON object in ``path``; DataError naming it when it is missing, too large, not
    JSON (nested too deeply for the parser included) or not an object."""
    try:
        value = parse_json(read_record_text(path))
    except FileNotFoundError:
        raise DataError(f"{path}: missing; is {path.parent} a homebench run folder?") from None
    except (OSError, ValueError) as error:
        raise DataError(f"{path}: corrupt ({error})") from None
    if not isinstance(value, dict):
        raise DataError(f"{path}: corrupt (expected a JSON object)")
    return value


def read_run_info(run_dir: Path) -> RunInfo:
    """Read a run folder's config and environment; DataError naming the file (and key) when
    it is not a run folder, a file is corrupt, or the environment does not fit its schema
    (:class:`~homebench.report.environment_record.EnvironmentRecord`; the config is checked
    by the reader of its kind)."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise DataError(f"{run_dir}: no such run folder")
    config, environment = (_read_json(run_dir / name) for name in (CONFIG_FILE, ENVIRONMENT_FILE))
    try:
        EnvironmentRecord.model_validate(environment)
    except ValidationError as error:
        raise validation_error(run_dir / ENVIRONMENT_FILE, "", error) from None
    return RunInfo(run_dir, config, environment)


def validation_error(path: Path, prefix: str, error: ValidationError) -> DataError:
    """``error``'s first problem as a DataError naming ``path`` and the key under ``prefix``."""
    first = error.errors()[0]
    where = ".".join(str(p) for p in (prefix, *first["loc"]) if p != "")
    message = first["msg"].removeprefix("Value error, ")
    return DataError(f"{path}: {where}: {message}" if where else f"{path}: {message}")


def grid_run(info: RunInfo, tables: RunTables | None = None) -> RunData:
    """The settings and tables of a grid run: ``tables`` when the caller has built them from
    this folder with its config's metrics (as ``homebench run`` has), else read here.
    DataError naming the file and key when its resolved config does not fit its schema
    (:class:`~homebench.config.ResolvedRunConfig`).

    Missing or corrupt job files do not raise: they are listed in ``tables.missing_jobs``.
    """
    try:
        settings = ResolvedRunConfig.model_validate(info.config)
    except ValidationError as error:
        raise validation_error(info.run_dir / CONFIG_FILE, "", error) from None
    if tables is None:
        tables = build_tables(info.run_dir, settings.metrics)
    return RunData(info.run_dir, info.config, info.environment, settings, tables)


def load_run(run_dir: Path) -> RunData:
    """Read a grid run folder; DataError naming the file when it is not one or is corrupt."""
    return grid_run(read_run_info(run_dir))
