"""Where a run's results come from: ``config.resolved.json`` and ``environment.json``.

The resolved config is the config as run: the number of workers and the job limits used, and
every method parameter with its default filled in. The environment holds the homebench source's
git commit (and whether its files differ from it; None when the package is not a git checkout),
host, platform, CPU model, Python, the version of every installed distribution, the host's
1-min load average as the run call began (``load``; a grid run adds it as the call ended and how
many jobs the call timed and reused: :func:`record_load_end`), and for a grid run each method's
distribution, version and code version, each database's identity, key (what its images hold)
and manifest hash, the command line and the options that overrode the config.
"""

from __future__ import annotations

import contextlib
import json
import os
import platform
import socket
import subprocess
import sys
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, distributions, version
from pathlib import Path
from typing import Any

from pydantic import BaseModel

import homebench
from homebench.config import RunConfig, SweptWorld
from homebench.evaluation.executors import Execution
from homebench.evaluation.isolation import Limits
from homebench.evaluation.plan import Plan
from homebench.evaluation.sources import Source, open_source
from homebench.fileio import write_text_atomic
from homebench.hashing import stable_hash
from homebench.methods import registry

ENVIRONMENT_FILE = "environment.json"
#: The packages the report's title page lists (``versions``).
PACKAGES = ("homebench", "numpy", "opencv-contrib-python-headless", "pandas", "joblib", "pydantic")


def _git(folder: Path, *args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=30
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout if done.returncode == 0 else None


def git_state(folder: Path) -> dict[str, Any] | None:
    """``{"commit", "dirty"}`` of the git checkout holding ``folder`` (dirty: a file under
    ``folder`` differs from the commit or is untracked), or None when there is none."""
    commit = _git(folder, "rev-parse", "HEAD")
    if commit is None:
        return None
    status = _git(folder, "status", "--porcelain", "--", ".")
    return {"commit": commit.strip(), "dirty": None if status is None else bool(status.strip())}


def cpu_model() -> str:
    """The CPU's model name (Linux: /proc/cpuinfo), else what the platform says."""
    with contextlib.suppress(OSError), open("/proc/cpuinfo", encoding="utf-8") as f:
        for line in f:
            if line.startswith("model name"):
                return line.partition(":")[2].strip()
    return platform.processor() or platform.machine()


def installed_distributions() -> dict[str, str]:
    """Every installed distribution's version, by name."""
    found = {}
    for dist in distributions():
        metadata = dist.metadata  # parsed on every access: once per distribution
        name = metadata["Name"]
        if name:
            found.setdefault(name, metadata["Version"])
    return dict(sorted(found.items(), key=lambda item: item[0].lower()))


def load_average() -> float | None:
    """The host's 1-min load average (processes running or waiting for a core), or None where
    the platform does not report it."""
    try:
        return float(os.getloadavg()[0])
    except (OSError, AttributeError):
        return None


def record_load_end(run_dir: Path, jobs_timed: int, jobs_reused: int) -> None:
    """Add to ``run_dir``'s environment.json the host's load as the run call ends
    (``load.end_1min``), the jobs the call timed and those it reused from earlier calls (whose
    times were measured under a load not recorded); nothing when there is no record."""
    path = run_dir / ENVIRONMENT_FILE
    try:
        environment = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    load = environment.get("load") if isinstance(environment.get("load"), dict) else {}
    environment["load"] = {**load, "end_1min": load_average(), "jobs_timed": jobs_timed,
                           "jobs_reused": jobs_reused}  # fmt: skip
    write_text_atomic(path, json.dumps(environment, indent=2, default=str) + "\n")


def _versions() -> dict[str, str]:
    found = {"python": sys.version.split()[0]}
    for name in PACKAGES:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = "not installed"
    return found


def environment(
    config_path: Path, resolved: dict[str, Any], extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """What ``environment.json`` holds; ``extra`` adds run-specific sections (methods,
    databases, overrides)."""
    return {
        "config_file": str(config_path),
        "config_hash": stable_hash(resolved, 64),
        "command": sys.argv,
        "homebench": homebench.__version__,
        "git": git_state(Path(homebench.__file__).resolve().parent),
        "versions": _versions(),
        "host": socket.gethostname(),
        "platform": platform.platform(),
        "cpu": {"model": cpu_model(), "count": os.cpu_count()},
        "cpu_count": os.cpu_count(),
        "started": datetime.now(UTC).isoformat(timespec="seconds"),
        "load": {"start_1min": load_average()},
        **(extra or {}),
        "distributions": installed_distributions(),
    }


def write_run_metadata(
    config: BaseModel,
    config_path: Path,
    run_dir: Path,
    resolved: dict[str, Any] | None = None,
    extra: dict[str, Any] | None = None,
) -> None:
    """The resolved config (``resolved``, default: the config as validated) and the
    environment (see :mod:`~homebench.evaluation.provenance`), beside the results."""
    resolved = resolved if resolved is not None else config.model_dump(mode="json")
    text = json.dumps(resolved, indent=2, default=str) + "\n"
    write_text_atomic(run_dir / "config.resolved.json", text)
    env = environment(config_path, json.loads(text), extra)
    write_text_atomic(run_dir / ENVIRONMENT_FILE, json.dumps(env, indent=2, default=str) + "\n")


def resolve_config(
    config: RunConfig,
    execution: Execution,
    limits: Limits,
    claims: list[dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """The config as run: the execution values used (workers, job ``limits``), every method
    parameter's value and the ``claims`` as recorded (with when each was stated:
    :func:`~homebench.evaluation.claims_record.stamped_claims`; default: as configured)."""
    resolved = config.model_dump(mode="json")
    resolved.update(
        jobs=execution.workers, job_timeout_s=limits.timeout_s, worker_memory_mb=limits.memory_mb
    )
    if claims is not None:
        resolved["claims"] = claims
    if not resolved["claims"]:  # as recorded before configs had claims: old runs still match
        del resolved["claims"]
    for entry in resolved["methods"]:
        defaults = registry.parameters(entry["method"])
        entry["params"] = {
            **{k: v for k, v in defaults.items() if k not in entry["grid"]},
            **entry["params"],
        }
    return resolved


def overrides(config: RunConfig, execution: Execution, force: bool) -> dict[str, Any]:
    """The options of a run that differ from its config (or from their defaults)."""
    given = {
        "jobs": (execution.jobs, config.jobs),
        "job_timeout_s": (execution.timeout_s, config.job_timeout_s),
        "worker_memory_mb": (execution.memory_mb, config.worker_memory_mb),
        "backend": (execution.backend, "local"),
        "scheduler": (execution.scheduler, None),
        "shard": (list(execution.shard) if execution.shard else None, None),
        "retry_failed": (execution.retry_failed, False),
        "force": (force, False),
    }
    return {key: value for key, (value, default) in given.items() if value != default}


def run_sections(
    config: RunConfig,
    execution: Execution,
    force: bool,
    plan: Plan,
    sources: dict[tuple[str, SweptWorld], Source],
) -> dict[str, Any]:
    """environment.json's sections of a grid run: methods, databases and overrides."""
    methods = {}
    for spec in {job.method.method: job.method for job in plan.home}.values():
        origin = registry.distribution(registry.get(spec.method))
        dist, version = origin if origin is not None else (None, None)
        methods[spec.method] = {"distribution": dist, "version": version, "code_version": spec.code}
    databases = {}
    for (alias, world), source in sorted(sources.items(), key=lambda item: str(item[0])):
        manifest = open_source(source).manifest.model_dump(mode="json")
        swept = "/".join(str(v) for v in world if v is not None)
        databases[f"{alias}@{swept}" if swept else alias] = {
            "name": manifest["name"],
            "identity": source.identity,
            "key": source.database_key,
            "locator": source.locator,
            "manifest_sha256": stable_hash(manifest, 64),
        }
    return {
        "methods": methods,
        "databases": databases,
        "overrides": overrides(config, execution, force),
    }
