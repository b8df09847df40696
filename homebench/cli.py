"""The homebench command line: parse, call the library, print. No logic lives here.

Exit codes: 0 success; 1 a crash (a bug: full traceback with ``--debug``) or failed jobs;
2 a usage, config or data error (one line naming the file or key); 3 a failed ``--check``
threshold (a regression, not a crash).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import click

from homebench import __version__
from homebench.errors import HomebenchError

EXIT_ERROR = 2
EXIT_CRASH = 1
EXIT_CHECK = 3


class _Group(click.Group):
    """Turns HomebenchError into one line and exit 2, any other exception into exit 1."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except HomebenchError as error:
            if ctx.find_root().params.get("debug"):
                raise
            for line in str(error).splitlines():
                click.echo(f"homebench: error: {line}", err=True)
            ctx.exit(EXIT_ERROR)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.Abort):
            raise
        except Exception as error:
            if ctx.find_root().params.get("debug"):
                raise
            click.echo(
                f"homebench: crash: {type(error).__name__}: {error} "
                "(rerun with --debug for the traceback)",
                err=True,
            )
            ctx.exit(EXIT_CRASH)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="homebench")
@click.option("--debug", is_flag=True, help="Show full tracebacks instead of one-line errors.")
def main(debug: bool) -> None:
    """Benchmark robot visual homing methods on panoramic grid image databases."""


# --------------------------------------------------------------------------- data


@main.group(cls=_Group)
def data() -> None:
    """Grid databases: list, generate, verify, show."""


@data.command("list")
def data_list() -> None:
    """List the known databases, where their files are, and whether they are present."""
    from homebench.data.catalog import list_databases

    rows = list_databases()
    width = max(len(r.name) for r in rows)
    for r in rows:
        state = "present" if r.present else "missing"
        click.echo(f"{r.name:<{width}}  {r.kind:<9}  {state:<7}  {r.location}")


@data.command("generate")
@click.argument("database")
@click.option(
    "--variant", "variants", multiple=True, help="Generate this variant of the same world "
    "instead (repeatable): original, arboreal, chairs, day, twilight, winlit."
)  # fmt: skip
@click.option("--out", type=click.Path(path_type=Path), help="Folder to write (default: cache).")
@click.option("--jobs", "-j", type=int, default=-1, show_default=True, help="Parallel workers.")
def data_generate(database: str, variants: tuple[str, ...], out: Path | None, jobs: int) -> None:
    """Generate DATABASE (a generated set's name or manifest) and print its folder."""
    from homebench.data.catalog import ensure_generated, generate_variant

    if not variants:
        db = ensure_generated(database, out, jobs)
        click.echo(str(db.root))
        return
    for variant in variants:
        target = out / variant if out is not None and len(variants) > 1 else out
        db = generate_variant(database, variant, target, jobs)
        click.echo(str(db.root))


@data.command("verify")
@click.argument("database")
@click.option("--path", type=click.Path(path_type=Path), help="Folder of a real set's copy.")
def data_verify(database: str, path: Path | None) -> None:
    """Check a database's files (layout, sizes, sha256) against its manifest."""
    from homebench.data.catalog import find_manifest, resolve
    from homebench.data.verify import verify

    manifest, _ = find_manifest(database)
    report = verify(resolve(database, path), manifest)
    for warning in report.warnings:
        click.echo(f"homebench: warning: {warning}", err=True)
    click.echo(
        f"{report.name}: {report.n_images} images OK in {report.root} "
        f"({len(report.checked)} sha256 checked, {len(report.unchecked)} without a known sum)"
    )


@data.command("show")
@click.argument("database")
@click.option("--path", type=click.Path(path_type=Path), help="Folder of a real set's copy.")
@click.option(
    "--out", type=click.Path(path_type=Path), default=Path("."), show_default=True,
    help="Folder for the PNG.",
)  # fmt: skip
@click.option("--at", nargs=2, type=int, help="Grid position shown large (default: centre).")
def data_show(database: str, path: Path | None, out: Path, at: tuple[int, int] | None) -> None:
    """Write a contact sheet PNG of DATABASE (the grid, one raw + unfolded pair)."""
    from homebench.data.catalog import resolve
    from homebench.report.contact_sheet import write_contact_sheet

    db = resolve(database, path)
    db.check_layout()
    sample = at or (db.grid.shape[0] // 2, db.grid.shape[1] // 2)
    out.mkdir(parents=True, exist_ok=True)
    written = write_contact_sheet(db, out / f"{db.name}_contact_sheet.png", sample)
    click.echo(str(written))


# --------------------------------------------------------------------------- methods and runs


@main.command()
def methods() -> None:
    """List the registered homing methods with their parameters and defaults."""
    from homebench.methods import registry

    for name, cls in registry.available().items():
        summary = " ".join((cls.__doc__ or "").strip().split("\n\n")[0].split())
        click.echo(f"{name} ({cls.image_kind} images): {summary}")
        for param, default in registry.parameters(name).items():
            click.echo(f"    {param} = {default!r}")


def _format_summary(summary: Any) -> str:
    shown = summary.copy()
    columns = {
        "condition": "condition",
        "method": "method",
        "pairs": "pairs",
        "no_estimate_share": "no est.",
        "mean_ae_deg": "mean AE [deg]",
        "median_ae_deg": "median AE [deg]",
        "ahc": "AHC",
        "rr": "RR",
        "describe_ms": "describe [ms/img]",
        "home_ms": "home [ms/pair]",
    }
    shown = shown[[c for c in columns if c in shown.columns]].rename(columns=columns)
    return shown.to_string(index=False, float_format=lambda v: "-" if math.isnan(v) else f"{v:.3g}")


def _run_routes(
    config_file: Path, jobs: int | None, force: bool, no_progress: bool, no_report: bool
) -> None:
    """``homebench run`` of a route-homing config (``kind: route``)."""
    from homebench.evaluation.route_homing import run_route_experiment
    from homebench.route_config import load_route_config

    config = load_route_config(config_file)
    outcome = run_route_experiment(
        config, config_file, jobs=jobs, force=force, show_progress=not no_progress
    )
    if not outcome.table.empty:
        click.echo(outcome.table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    click.echo(
        f"{outcome.computed} trial(s) computed, {outcome.reused} reused; "
        f"table in {outcome.table_path}"
    )
    if not no_report and not outcome.table.empty:
        from homebench.report.document import write_report

        click.echo(f"report: {write_report(outcome.run_dir).files[-1]}")
    for failure in outcome.failures:
        click.echo(f"homebench: trial {failure.key} failed: {failure.error}", err=True)
    if outcome.failures:
        sys.exit(EXIT_CRASH)


def _parse_shard(
    ctx: click.Context, param: click.Parameter, value: str | None
) -> tuple[int, int] | None:
    if value is None:
        return None
    try:
        i, n = (int(part) for part in value.split("/"))
    except ValueError:
        raise click.BadParameter(f"{value!r} is not i/N (e.g. 2/8)") from None
    return i, n


@main.command()
@click.argument("config_file", type=click.Path(path_type=Path))
@click.option("--jobs", "-j", type=int, help="Parallel workers (overrides the config; -1 all).")
@click.option("--force", is_flag=True, help="Recompute every job, even finished ones.")
@click.option("--no-progress", is_flag=True, help="Hide the progress bars.")
@click.option("--no-report", is_flag=True, help="Skip the PDF report (tables are still written).")
@click.option(
    "--backend", type=click.Choice(["local", "dask"]), default="local", show_default=True,
    help="local: joblib workers on this machine; dask: a Dask cluster (see --scheduler).",
)  # fmt: skip
@click.option("--scheduler", help="Address of a running Dask scheduler (default: local cluster).")
@click.option(
    "--shard", callback=_parse_shard, metavar="I/N",
    help="Run only the I-th of N deterministic parts of the plan (1-based).",
)  # fmt: skip
@click.option(
    "--check", is_flag=True, help="Compare metrics with the config's thresholds; exit 3 on failure."
)
def run(
    config_file: Path,
    jobs: int | None,
    force: bool,
    no_progress: bool,
    no_report: bool,
    backend: str,
    scheduler: str | None,
    shard: tuple[int, int] | None,
    check: bool,
) -> None:
    """Run the benchmark described by CONFIG_FILE; resumes an interrupted run."""
    from homebench.config import config_kind, load_config
    from homebench.errors import ConfigError
    from homebench.evaluation.results import build_tables, write_tables
    from homebench.evaluation.runner import Execution, run_plan

    if config_kind(config_file) == "route":
        if backend != "local" or shard is not None or check:
            raise ConfigError("--backend dask, --shard and --check are for grid runs, not routes")
        _run_routes(config_file, jobs, force, no_progress, no_report)
        return
    config = load_config(config_file)
    execution = Execution(
        jobs=jobs if jobs is not None else config.jobs,
        backend=backend,
        scheduler=scheduler,
        shard=shard,
    )
    outcome = run_plan(config, config_file, execution, force=force, show_progress=not no_progress)
    tables = build_tables(outcome.run_dir, config.metrics)
    written = write_tables(tables, outcome.run_dir, config.table_format)
    if not tables.summary.empty:
        click.echo(_format_summary(tables.summary))
    click.echo(
        f"{outcome.computed} job(s) computed, {outcome.reused} reused; "
        f"tables in {written[0].parent}"
    )
    if tables.missing_jobs:
        click.echo(
            f"{len(tables.missing_jobs)} job(s) of the plan have no result here yet (other "
            "shards?): their rows are not in the tables; rerun or `homebench report` once all "
            "job files are in place"
        )
    if not no_report and not tables.summary.empty:
        from homebench.report.document import write_report

        report_files = write_report(outcome.run_dir).files
        click.echo(f"report: {report_files[-1]}")
    for failure in outcome.failures:
        click.echo(f"homebench: job {failure.kind} {failure.key} failed: {failure.error}", err=True)
    if outcome.failures:
        sys.exit(EXIT_CRASH)
    if check:
        from homebench.evaluation.checks import failed_checks

        if not config.checks:
            raise ConfigError(f"{config_file}: --check needs a 'checks' section")
        reasons = failed_checks(tables.summary, config.checks)
        for reason in reasons:
            click.echo(f"homebench: check failed: {reason}", err=True)
        if reasons:
            sys.exit(EXIT_CHECK)
        click.echo(f"all {len(config.checks)} method check(s) passed")


# --------------------------------------------------------------------------- reports


@main.command()
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option(
    "--format", "formats", multiple=True, type=click.Choice(["pdf", "html", "md"]),
    default=("pdf",), show_default=True, help="Report documents to write (repeatable).",
)  # fmt: skip
@click.option("--out", type=click.Path(path_type=Path), help="Folder (default: RUN_DIR/report).")
@click.option(
    "--max-goals", type=click.IntRange(min=1), default=4, show_default=True,
    help="Goals per condition drawn as vector fields and AE maps.",
)  # fmt: skip
def report(run_dir: Path, formats: tuple[str, ...], out: Path | None, max_goals: int) -> None:
    """Write the tables, figures and PDF report of the run in RUN_DIR."""
    from homebench.report.document import write_report

    outcome = write_report(run_dir, formats, out, max_goals)
    for warning in outcome.warnings:
        click.echo(f"homebench: warning: missing job result {warning}", err=True)
    for path in outcome.files:
        click.echo(str(path))


@main.command()
@click.argument("run_dirs", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--out", type=click.Path(path_type=Path), help="Also write the table here.")
def compare(run_dirs: tuple[Path, ...], out: Path | None) -> None:
    """Compare runs with the first one: AE, AHC, RR differences and time ratios."""
    from homebench.report.compare import compare_runs
    from homebench.report.tables import to_markdown, write_views

    comparison = compare_runs(run_dirs)
    for warning in comparison.warnings:
        click.echo(f"homebench: warning: {warning}", err=True)
    click.echo(to_markdown(comparison.view()))
    if out is not None:
        for path in write_views([comparison.view()], out):
            click.echo(str(path))
