"""The report's appendix as text: the run's resolved config, its environment and the data sets'
checksums, read from ``config.resolved.json`` and ``environment.json``
(:mod:`homebench.evaluation.provenance`, :mod:`homebench.evaluation.data_checks`).

A key the run did not record (an older run folder, a route run has no databases) reads
"not recorded"; nothing here raises on a sparse environment.
"""

from __future__ import annotations

import json
import shlex
from dataclasses import dataclass
from typing import Any

from homebench.config import MetricsConfig
from homebench.report.definitions import definitions
from homebench.report.run_data import RunInfo

#: Containers whose JSON fits in this many characters (with their indent) stay on one line.
INLINE_WIDTH = 72
#: Files named per database whose content differs from the reference, at most.
MAX_DIFFERING = 5
NOT_RECORDED = "not recorded"
#: Packages whose versions the environment page lists (from ``versions``, else from every
#: installed ``distributions``).
KEY_PACKAGES = ("numpy", "scipy", "opencv-contrib-python-headless", "pandas", "matplotlib",
                "joblib", "pydantic", "tqdm")  # fmt: skip
#: Headings of the appendix's parts, in every report format.
DEFINITIONS_TITLE = "Definitions: metrics and statistics"
CONFIG_TITLE = "Configuration (config.resolved.json)"
ENVIRONMENT_TITLE = "Environment and data checksums (environment.json)"


@dataclass(frozen=True)
class Appendix:
    """``definitions``: heading -> paragraphs (empty for a route run); ``config``: the
    resolved config as JSON lines; ``environment``: heading -> lines."""

    definitions: dict[str, list[str]]
    config: list[str]
    environment: dict[str, list[str]]


def json_lines(value: Any, prefix: str = "", indent: str = "", suffix: str = "") -> list[str]:
    """``value`` as indented JSON lines; a container that fits INLINE_WIDTH stays on one line."""
    flat = json.dumps(value, ensure_ascii=False)
    if not isinstance(value, dict | list) or len(indent + prefix + flat) <= INLINE_WIDTH:
        return [f"{indent}{prefix}{flat}{suffix}"]
    items = list(value.items()) if isinstance(value, dict) else [(None, v) for v in value]
    opening, closing = "{}" if isinstance(value, dict) else "[]"
    lines = [f"{indent}{prefix}{opening}"]
    for k, (key, item) in enumerate(items):
        key_text = "" if key is None else f"{json.dumps(key, ensure_ascii=False)}: "
        lines += json_lines(item, key_text, indent + "  ", "," if k < len(items) - 1 else "")
    return [*lines, f"{indent}{closing}{suffix}"]


def _recorded(value: Any) -> str:
    return NOT_RECORDED if value is None else str(value)


def _git_text(env: dict[str, Any]) -> str:
    """The git commit and whether files differed from it (None: not a git checkout)."""
    if "git" not in env:
        return NOT_RECORDED
    git = env["git"]
    if not isinstance(git, dict):
        return "not a git checkout"
    dirty = {True: "dirty: files differed from the commit", False: "clean"}
    return f"{git.get('commit')} ({dirty.get(git.get('dirty'), 'state unknown')})"


def _software(env: dict[str, Any]) -> list[str]:
    versions = env.get("versions", {})
    installed = {**env.get("distributions", {}), **versions}
    return [
        f"homebench: {_recorded(env.get('homebench', versions.get('homebench')))}",
        f"git commit: {_git_text(env)}",
        f"python: {_recorded(versions.get('python'))}",
        "packages: "
        + ", ".join(f"{name} {_recorded(installed.get(name))}" for name in KEY_PACKAGES),
    ]


def _machine(env: dict[str, Any]) -> list[str]:
    cpu = env.get("cpu") if isinstance(env.get("cpu"), dict) else {}
    return [
        f"host: {_recorded(env.get('host'))}",
        f"platform: {_recorded(env.get('platform'))}",
        f"CPU: {_recorded(cpu.get('model'))}, {_recorded(cpu.get('count', env.get('cpu_count')))}"
        " logical CPUs",
    ]


def _invocation(env: dict[str, Any]) -> list[str]:
    command = env.get("command")
    overrides = env.get("overrides")
    return [
        f"started: {_recorded(env.get('started'))}",
        f"command: {shlex.join(command) if isinstance(command, list) else _recorded(command)}",
        f"config file: {_recorded(env.get('config_file'))}",
        f"config hash (sha256 of the resolved config): {_recorded(env.get('config_hash'))}",
        "overrides: " + (json.dumps(overrides) if overrides is not None else NOT_RECORDED),
    ]


def _methods(env: dict[str, Any]) -> list[str]:
    methods = env.get("methods")
    if not isinstance(methods, dict) or not methods:
        return [NOT_RECORDED]
    return [
        f"{name}: {m.get('distribution')} {m.get('version')}, code version {m.get('code_version')}"
        for name, m in methods.items()
    ]


def _check_text(check: dict[str, Any]) -> str:
    differing = list(check.get("differing", []))
    shown = ", ".join(differing[:MAX_DIFFERING]) + (" ..." if len(differing) > MAX_DIFFERING
                                                    else "")  # fmt: skip
    return (
        f"against {check.get('reference')}: {check.get('identical')} of {check.get('checked')} "
        f"files byte-identical, {check.get('tolerated')} equal in content (fingerprint), "
        f"{len(differing)} differing" + (f" ({shown})" if differing else "")
    )


def _data(env: dict[str, Any]) -> list[str]:
    databases = env.get("databases")
    if not isinstance(databases, dict) or not databases:
        lines = [f"databases: {NOT_RECORDED}"]
    else:
        lines = [
            f"{alias}: {d.get('identity')}, manifest sha256 {d.get('manifest_sha256')}, "
            f"at {d.get('locator')}"
            for alias, d in databases.items()
        ]
    checks = env.get("data_checks")
    if not isinstance(checks, dict):
        return [*lines, f"reference checks: {NOT_RECORDED}"]
    if not checks:
        return [*lines, "reference checks: no database has reference sums"]
    return [*lines, *(f"check of {name}: {_check_text(c)}" for name, c in checks.items())]


def environment_sections(env: dict[str, Any]) -> dict[str, list[str]]:
    """environment.json as headed lines: software, machine, invocation, methods, data."""
    return {
        "Software": _software(env),
        "Machine": _machine(env),
        "Invocation": _invocation(env),
        "Methods (code versions)": _methods(env),
        "Data sets (manifest checksums and reference checks)": _data(env),
    }


def run_appendix(run: RunInfo, metrics: MetricsConfig | None) -> Appendix:
    """The appendix of ``run``; ``metrics``: a grid run's metric settings (None: a route or
    closed-loop run, which has no grid metrics to define)."""
    return Appendix(
        {} if metrics is None else definitions(metrics),
        json_lines(run.config),
        environment_sections(run.environment),
    )
