"""The schema of a run folder's ``environment.json`` as its readers use it: every field they
read has its type checked (a field a run of an older homebench did not record may be absent;
fields no reader uses are left as they are).

The writer is :func:`homebench.evaluation.provenance.environment`.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict


class _Record(BaseModel):
    model_config = ConfigDict(extra="allow", strict=True)


class _Git(_Record):
    commit: str | None = None
    dirty: bool | None = None


class _Cpu(_Record):
    model: str | None = None
    count: int | None = None


class _Method(_Record):
    distribution: str | None = None
    version: str | None = None
    code_version: str | None = None


class _Database(_Record):
    name: str | None = None
    identity: str | None = None
    key: str | None = None
    locator: str | None = None
    manifest_sha256: str | None = None


class _Load(_Record):
    """The host's 1-min load average as the run call began and ended, and the jobs that call
    timed and reused (the latter timed in earlier calls); an interrupted call has no end."""

    start_1min: float | None = None
    end_1min: float | None = None
    jobs_timed: int | None = None
    jobs_reused: int | None = None


class EnvironmentRecord(_Record):
    """``environment.json``: what a run recorded of where its results come from."""

    config_file: str | None = None
    config_hash: str | None = None
    command: list[str] | None = None
    homebench: str | None = None
    git: _Git | None = None
    versions: dict[str, str] = {}
    host: str | None = None
    platform: str | None = None
    cpu: _Cpu | None = None
    cpu_count: int | None = None
    started: str | None = None
    load: _Load | None = None  # not recorded before homebench recorded the load
    methods: dict[str, _Method] = {}
    databases: dict[str, _Database] = {}
    overrides: dict[str, Any] | None = None
    data_checks: dict[str, dict[str, Any]] | None = None
    distributions: dict[str, str | None] = {}
