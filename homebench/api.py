"""The Python API: run a grid config, read a run's tables as pandas frames, draw one figure.

For notebooks and scripts; ``homebench run`` uses the same engine (:func:`run_grid`)::

    from homebench import api

    run_dir = api.run("configs/quickstart.yaml", ["methods.0.params.n_rho=10"], jobs=2)
    t = api.tables(run_dir)
    t.summary[["condition", "method", "mean_ae_deg", "mean_ae_deg_lo", "mean_ae_deg_hi"]]
    names = api.figure_names(run_dir)    # the report's figures by file stem
    fig = api.figure(run_dir, names[0])  # a matplotlib Figure

Errors are :class:`homebench.errors.HomebenchError` (ConfigError, DataError) of one line, as
on the command line.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from homebench.analysis.tables import RunTables
from homebench.config import RunConfig, grid_config, kind_of, load_config
from homebench.errors import ConfigError, DataError
from homebench.evaluation.executors import Execution
from homebench.evaluation.results import build_tables, write_tables
from homebench.evaluation.runner import RunOutcome, run_plan
from homebench.suggest import unknown
from homebench.yamlio import read_yaml

if TYPE_CHECKING:  # matplotlib is imported by the functions that draw
    from matplotlib.figure import Figure

__all__ = ["GridRun", "Tables", "figure", "figure_names", "run", "run_grid", "tables"]


@dataclass(frozen=True)
class GridRun:
    """A grid config's run: the config as loaded, what the engine did, the tables it wrote."""

    config: RunConfig
    outcome: RunOutcome
    tables: RunTables
    files: list[Path]  # the tables written under the run folder's tables/


def run_grid(
    config_path: Path,
    overrides: Sequence[str] = (),
    *,
    config: RunConfig | None = None,
    jobs: int | None = None,
    timeout_s: float | None = None,
    backend: str = "local",
    scheduler: str | None = None,
    shard: tuple[int, int] | None = None,
    retry_failed: bool = False,
    force: bool = False,
    update: bool = False,
    show_progress: bool = True,
) -> GridRun:
    """Run a grid config (``key=value`` ``overrides`` applied) and write its tables: the
    engine of ``homebench run``, whose options the keywords are (``jobs`` and ``timeout_s``
    default to the config's). ``config``: the config as read from ``config_path`` with
    ``overrides``, by a caller that read it to learn its kind (read here when None: a file is
    read once). ``show_progress`` shows the bars of world generation (on a terminal) and of the
    jobs."""
    from homebench.data.progress import progress_bars

    if config is None:
        config = load_config(Path(config_path), overrides)
    execution = Execution(
        jobs=jobs if jobs is not None else config.jobs,
        backend=backend,
        scheduler=scheduler,
        shard=shard,
        timeout_s=timeout_s if timeout_s is not None else config.job_timeout_s,
        memory_mb=config.worker_memory_mb,
        retry_failed=retry_failed,
    )
    with progress_bars(show_progress):
        outcome = run_plan(
            config,
            Path(config_path),
            execution,
            force=force,
            update=update,
            overrides=overrides,
            show_progress=show_progress,
        )
    tables = build_tables(outcome.run_dir, config.metrics)
    files = write_tables(tables, outcome.run_dir, config.table_format)
    return GridRun(config, outcome, tables, files)


def run(
    config_path: str | Path,
    overrides: Sequence[str] = (),
    jobs: int | None = None,
    run_dir: str | Path | None = None,
    *,
    report: bool = False,
    progress: bool = True,
) -> Path:
    """Run the grid config at ``config_path`` as ``homebench run`` does; return the run folder.

    ``overrides``: ``key.path=value`` settings (``"methods.0.params.n_rho=10"``); ``jobs``:
    workers (default: the config's; -1 all cores); ``run_dir``: the run folder (default: the
    config's ``output``); ``report``: also write the PDF report; ``progress``: show progress
    bars. Finished jobs are reused. Failed jobs are recorded in the run folder and their pairs
    carry the error; this warns once.
    """
    config_path = Path(config_path)
    if run_dir is not None:  # a JSON string is a YAML string: any path survives the parser
        overrides = [*overrides, f"output={json.dumps(str(run_dir))}"]
    document = read_yaml(config_path, "config", overrides)  # the one read of the file
    kind = kind_of(document.data)
    if kind != "grid":
        raise ConfigError(f"{config_path}: a {kind} config; run it with `homebench run`")
    config = grid_config(document)
    done = run_grid(config_path, overrides, config=config, jobs=jobs, show_progress=progress)
    pairs = done.tables.pairs
    failed = len(done.outcome.failures) + (int(pairs["error"].notna().sum()) if len(pairs) else 0)
    if failed:
        warnings.warn(
            f"{failed} failed job(s) or pair(s) in {done.outcome.run_dir}: see its failures/ "
            "and the pairs' error column",
            stacklevel=2,
        )
    if report and not done.tables.summary.empty:
        from homebench.report.document import write_report

        write_report(done.outcome.run_dir, tables=done.tables)
    return done.outcome.run_dir


@dataclass(frozen=True)
class Tables:
    """A grid run's tables as pandas frames (the columns of ``RUN/tables/*.csv``).

    ``summary``: one row per condition and method, each metric with its 95 % interval
    (``*_lo``, ``*_hi``); ``pairs``: one row per (goal, current) pair, angles in degrees
    (``*_deg``); ``goals``: per goal; ``ahc``: per distance bin; ``bands``: the headline
    metrics per distance band; ``rr_starts``: every return-ratio start; ``summary_by_seed``:
    per world seed (empty unless seeds are swept); ``missing_jobs``: jobs without a result
    (other shards, failures).
    """

    summary: pd.DataFrame
    pairs: pd.DataFrame
    goals: pd.DataFrame
    ahc: pd.DataFrame
    bands: pd.DataFrame
    rr_starts: pd.DataFrame
    summary_by_seed: pd.DataFrame
    missing_jobs: tuple[str, ...]
    _run: RunTables = field(repr=False, compare=False)

    @property
    def comparisons(self) -> pd.DataFrame:
        """Every pair of methods within each condition: differences of mean AE, AHC and RR
        (B - A) with intervals and Holm-adjusted p-values (see
        :func:`homebench.analysis.comparisons.comparison_table`); computed on first use."""
        return self._run.comparisons if not self.pairs.empty else pd.DataFrame()


def tables(run_dir: str | Path) -> Tables:
    """The tables of the grid run in ``run_dir``, rebuilt from its job files (no report needed).

    DataError (one line) when the folder is no run folder or holds a route run.
    """
    from homebench.report.run_data import grid_run, read_run_info

    info = read_run_info(Path(run_dir))
    if info.kind != "grid":
        raise DataError(f"{run_dir}: a {info.kind} run; its tables are in tables/ there")
    t = grid_run(info).tables
    return Tables(t.summary, t.pairs, t.goals, t.ahc, t.bands, t.rr_starts, t.summary_by_seed,
                  t.missing_jobs, t)  # fmt: skip


def figure_names(run_dir: str | Path) -> list[str]:
    """The file stems of the report's figures of ``run_dir``, in the report's order (every
    figure is drawn to find them: a few seconds)."""
    from homebench.report.document import load_content
    from homebench.report.style import report_style

    names = []
    with report_style():
        for stem, _, _, fig in load_content(Path(run_dir)).figures():
            _close(fig)
            names.append(stem)
    return names


def figure(run_dir: str | Path, stem: str) -> Figure:
    """The report's figure whose PNG is ``<stem>.png`` (see :func:`figure_names`), drawn
    with the report's style; the figures drawn before it are closed. DataError naming the
    closest stem when none matches."""
    from homebench.report.document import load_content
    from homebench.report.style import report_style

    seen = []
    with report_style():
        for name, _, _, fig in load_content(Path(run_dir)).figures():
            if name == stem:
                return fig
            _close(fig)
            seen.append(name)
    raise DataError(f"{run_dir}: " + unknown("figure", stem, seen))


def _close(fig: Figure) -> None:
    import matplotlib.pyplot as plt

    plt.close(fig)
