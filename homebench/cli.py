"""The homebench command line: parse, call the library, print. No logic lives here.

Exit codes: 0 success; 1 a crash (a bug: full traceback with ``--debug``) or failed jobs;
2 a usage, config or data error, or a file the operating system refuses (one line naming the
file or key); 3 a failed ``--check`` threshold (a regression, not a crash); 130 stopped by
Ctrl-C (one line: what a run saved).
"""

from __future__ import annotations

import errno
import os
import re
import signal
import sys
from pathlib import Path
from typing import Any, Literal

import click

from homebench import __version__
from homebench.address_space import check_run_space, reserve_less
from homebench.errors import HomebenchError, Interrupted
from homebench.report import DEFAULT_MAX_GOALS

EXIT_ERROR = 2
EXIT_CRASH = 1
EXIT_CHECK = 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports it


class _Group(click.Group):
    """Turns HomebenchError into one line and exit 2, and so an OSError (a run folder that is a
    file, a read-only disk, a symbolic link loop: the system refused, homebench has no bug);
    Ctrl-C into one line and exit 130; any other exception is a crash, exit 1. A broken pipe
    is left to click."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except Interrupted as error:
            _say("", str(error))
            ctx.exit(EXIT_INTERRUPTED)
        except KeyboardInterrupt:
            _say("", "interrupted")
            ctx.exit(EXIT_INTERRUPTED)
        except HomebenchError as error:
            if ctx.find_root().params.get("debug"):
                raise
            _say("error: ", str(error))
            ctx.exit(EXIT_ERROR)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.Abort):
            raise
        except OSError as error:
            if ctx.find_root().params.get("debug") or error.errno == errno.EPIPE:
                raise
            _say("error: ", _os_error_line(error))
            ctx.exit(EXIT_ERROR)
        except Exception as error:
            if ctx.find_root().params.get("debug"):
                raise
            crash = f"{type(error).__name__}: {error}"
            _say("crash: ", f"{crash} (rerun with --debug for the traceback)")
            ctx.exit(EXIT_CRASH)


#: What a message must not print raw: control characters (a line feed starts a line of its
#: own), lone surrogates (a file name's bytes that are no UTF-8).
_UNPRINTABLE = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")


def _escaped(match: re.Match[str]) -> str:
    """A character of :data:`_UNPRINTABLE` as an escape: "\\x1b", "\\u2028"; a file name's
    undecodable byte as the byte: "\\xff"."""
    char = match[0]
    if "\udc80" <= char <= "\udcff":  # os.fsdecode's surrogate escape of a byte
        return f"\\x{ord(char) - 0xDC00:02x}"
    return char.encode("unicode_escape").decode("ascii")


def _say(kind: str, text: str) -> None:
    """``text`` on stderr, each of its lines as ``homebench: <kind><line>``, with what may not
    print raw escaped (:data:`_UNPRINTABLE`): a file name's bytes cannot move the cursor,
    clear the screen or start a line that does not say it is homebench's."""
    for line in _UNPRINTABLE.sub(_escaped, text).split("\n"):
        click.echo(f"homebench: {kind}{line}", err=True)


def _os_error_line(error: OSError) -> str:
    """An OSError as one line naming its file(s): "/runs/x: Read-only file system"."""
    files = " -> ".join(str(f) for f in (error.filename, error.filename2) if f is not None)
    reason = error.strerror or " ".join(str(error).split())
    return f"{files}: {reason}" if files else reason


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="homebench")
@click.option("--debug", is_flag=True, help="Show full tracebacks instead of one-line errors.")
def main(debug: bool) -> None:
    """Benchmark robot visual homing methods on panoramic grid image databases."""
    reserve_less()  # before pyarrow loads
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        # A shell starts a script's background jobs with Ctrl-C ignored; a user (or a batch
        # system) who sends homebench SIGINT all the same means it to stop.
        signal.signal(signal.SIGINT, signal.default_int_handler)


# --------------------------------------------------------------------------- data


@main.group(cls=_Group)
def data() -> None:
    """Databases (manifests, Brains on Board folders): list, generate, verify, show, check."""


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
@click.option(
    "--format", "layout", type=click.Choice(["homebench", "bob"]), default="homebench",
    show_default=True, help="homebench: raw/, unfolded/ and a manifest; bob: the Brains on Board "
    "image-database format (database_entries.csv), written to --out from the cached world.",
)  # fmt: skip
@click.option("--jobs", "-j", type=int, default=-1, show_default=True, help="Parallel workers.")
@click.option("--no-progress", is_flag=True, help="Hide the progress bar.")
def data_generate(
    database: str,
    variants: tuple[str, ...],
    out: Path | None,
    layout: str,
    jobs: int,
    no_progress: bool,
) -> None:
    """Generate DATABASE (a generated set's name or manifest); say what it made (world, grid,
    images, folder) and how long it took."""
    from functools import partial

    from homebench.data.bob import write_bob
    from homebench.data.catalog import ensure_generated, generate_variant
    from homebench.data.made import made_line, timed
    from homebench.data.progress import progress_bars
    from homebench.errors import ConfigError

    bob = layout == "bob"
    if bob and out is None:
        raise ConfigError("--format bob writes a new folder: give it with --out DIR")

    def made(generate: Any, target: Path | None) -> None:
        done = timed(generate)
        click.echo(made_line(done, write_bob(done.database, target) if bob else None))

    with progress_bars(not no_progress):
        if not variants:
            made(partial(ensure_generated, database, None if bob else out, jobs), out)
        for variant in variants:
            target = out / variant if out is not None and len(variants) > 1 else out
            folder = None if bob else target
            made(partial(generate_variant, database, variant, folder, jobs), target)


@data.command("verify")
@click.argument("database")
@click.option("--path", type=click.Path(path_type=Path), help="Folder of a real set's copy.")
def data_verify(database: str, path: Path | None) -> None:
    """Check a database's files (layout, sizes, sha256) against its manifest, or a Brains on
    Board database folder's against its database_entries.csv."""
    from homebench.data.catalog import find_manifest
    from homebench.data.verify import verify, verify_posed

    opened = _open_database(database, path)
    if opened.posed is not None:
        report = verify_posed(opened.posed)
        for warning in report.warnings:
            _say("warning: ", warning)
        click.echo(
            f"{opened.label}: {report.n_images} images OK in {report.root} "
            f"({opened.posed.layout()}; the format records no sums)"
        )
        return
    report = verify(opened.database, find_manifest(database)[0])
    for warning in report.warnings:
        _say("warning: ", warning)
    click.echo(report.line(opened.label))


@data.command("show")
@click.argument("database")
@click.option("--path", type=click.Path(path_type=Path), help="Folder of a real set's copy.")
@click.option(
    "--out", type=click.Path(path_type=Path), default=Path("."), show_default=True,
    help="Folder for the PNG.",
)  # fmt: skip
@click.option(
    "--at", nargs=2, type=int,
    help="Grid position shown large (default: centre); K 0 for image K of posed images.",
)  # fmt: skip
def data_show(database: str, path: Path | None, out: Path, at: tuple[int, int] | None) -> None:
    """Write a contact sheet PNG of DATABASE (the grid, one raw + unfolded pair; of posed
    images, a Brains on Board route say, a map of the poses beside one image)."""
    from homebench.data.check.travel import route_warnings
    from homebench.report.contact_sheet import centre_sample, write_contact_sheet, write_pose_sheet

    opened = _open_database(database, path)
    posed = opened.posed if opened.grid is None else None
    db = opened.database if posed is None else posed.database()
    db.check_layout()
    sample = at or centre_sample(db.grid)
    db.path(*sample, db.kinds[0])  # DataError naming the grid when --at is outside it
    out.mkdir(parents=True, exist_ok=True)
    if posed is not None:
        for warning in route_warnings(posed):
            _say("warning: ", f"{opened.label}: {warning}")
        written = write_pose_sheet(db, out / f"{db.name}_poses.png", sample[0], posed.layout())
        click.echo(f"{opened.label}: {posed.layout()}, not a grid; {written}")
        return
    written = write_contact_sheet(db, out / f"{db.name}_contact_sheet.png", sample)
    click.echo(str(written))


@data.command("check")
@click.argument("database")
@click.option("--path", type=click.Path(path_type=Path), help="Folder of a real set's copy.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the pairs homed.")
def data_check(database: str, path: Path | None, seed: int) -> None:
    """Estimate DATABASE's conventions from its images (a grid's label order, a route's
    headings, azimuth direction and zero, horizon, a raw image's centre) by homing and flow
    between grid neighbours or nearby posed images, and hold them against its manifest (a
    Brains on Board folder's homebench.yaml); exit 3, with the corrections to make, where they
    disagree."""
    from homebench.data.check import (
        METHOD,
        check_database,
        check_posed,
        posed_report_lines,
        report_lines,
    )

    opened = _open_database(database, path)
    if opened.grid is None:
        posed = check_posed(opened.posed, seed)
        click.echo(f"{opened.label}: {opened.posed.layout()}, images in {opened.posed.root}")
        click.echo("\n".join(posed_report_lines(posed, METHOD)))
        agrees = posed.agrees
    else:
        checks = check_database(opened.grid, seed)
        click.echo(f"{opened.label}: images in {opened.grid.root}")
        click.echo("\n".join(report_lines(checks, METHOD)))
        agrees = all(check.agrees for check in checks)
    if not agrees:
        sys.exit(EXIT_CHECK)


def _open_database(database: str, path: Path | None) -> Any:
    """The database as the data commands open and name it (homebench.data.naming); its
    manifest's warnings and the notes on what was assumed in reading it go to stderr."""
    from homebench.data.naming import open_database

    opened = open_database(database, path)
    for warning in opened.warnings:
        _say("warning: ", warning)
    for note in opened.notes:
        _say("note: ", note)
    return opened


# --------------------------------------------------------------------------- methods and runs


@main.command()
@click.argument("name", required=False)
@click.option(
    "--format", "fmt", type=click.Choice(["text", "md", "json"]), default="text",
    show_default=True, help="text for the terminal, md (Markdown) or json (stable keys).",
)  # fmt: skip
def methods(name: str | None, fmt: str) -> None:
    """List the registered homing methods, one line each; with NAME, that method's parameters:
    type, default, bounds, meaning and where it departs from (an opt-in option) or reads (an
    ambiguous passage of) its paper, and the paper."""
    from homebench.methods import registry
    from homebench.methods.cards import card, render_card, render_listing

    if name is None:
        cards = [card(n, cls) for n, cls in registry.available().items()]
        text = render_listing(cards, registry.broken(), fmt)  # type: ignore[arg-type]
    else:
        text = render_card(card(name, registry.get(name)), fmt)  # type: ignore[arg-type]
    try:
        click.echo(text)
        sys.stdout.flush()
    except BrokenPipeError:  # `homebench methods | head`: the reader has all it wants
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit


def _format_summary(tables: Any, config: Any) -> str:
    """The run's headline table (the report's first: the same cells, order and marks)."""
    from homebench.report.tables import config_order, console_summary

    order = config_order(config)
    metrics = tables.metrics
    return console_summary(
        tables.summary, order, tables.comparisons, metrics.ahc, metrics.return_ratio
    )


def _run_experiment(
    kind: str,
    config: Any,
    config_file: Path,
    jobs: int | None,
    force: bool,
    no_progress: bool,
    no_report: bool,
) -> None:
    """``homebench run`` of a robot experiment: a route (``kind: route``) or closed-loop
    homing ``config`` (``kind: closed-loop``), read from ``config_file``."""
    if kind == "route":
        from homebench.experiments.route.experiment import run_route_experiment as run_kind
    else:
        from homebench.experiments.closed_loop.experiment import (
            run_closed_loop_experiment as run_kind,
        )

    outcome = run_kind(config, config_file, jobs=jobs, force=force, show_progress=not no_progress)
    for note in outcome.notes:
        _say("note: ", note)
    if not outcome.table.empty:
        from homebench.report.consoles import experiment_console

        click.echo(experiment_console(kind, outcome.table, config))
    failed = f", {len(outcome.failures)} failed" if outcome.failures else ""
    click.echo(
        f"{outcome.computed} trial(s) computed, {outcome.reused} reused{failed}; "
        f"table in {outcome.table_path}"
    )
    if not no_report and not outcome.table.empty:
        from homebench.report.document import write_report

        report_files = write_report(outcome.run_dir, progress=not no_progress).files
        click.echo(f"report: {report_files[-1]}")
    for failure in outcome.failures:
        _say("", f"trial {failure.key} failed: {failure.error}")
    if outcome.failures:
        sys.exit(EXIT_CRASH)


def _report_failures(outcome: Any, pairs: Any) -> int:
    """One stderr line per failed job and per job with failed pairs, one on how to retry; the
    number of failed pairs."""
    import pandas as pd

    for failure in outcome.failures:
        attempt = f" (attempt {failure.attempts})" if failure.attempts > 1 else ""
        job = f"{failure.kind} {failure.key} ({failure.job})"
        _say("", f"job {job} failed{attempt}: {failure.cause}")
    failed = pairs[pairs["error"].notna()] if "error" in pairs else pd.DataFrame()
    if not failed.empty:
        goals = ["seed", "method", "condition", "goal_i", "goal_j"]
        for (seed, method, condition, i, j), group in failed.groupby(goals, dropna=False):
            swept = "" if pd.isna(seed) else f", seed {seed}"
            _say(
                "",
                f"job ({method}, {condition}, goal ({i}, {j}){swept}): {len(group)} pair(s) "
                f"failed: {group['error'].iloc[0]} (the pairs table holds every error)",
            )
    if not failed.empty or any(failure.kind == "home" for failure in outcome.failures):
        _say(
            "",
            "failed jobs are recorded in the run folder's failures/ and not run again; rerun "
            "with --retry-failed to retry them (and the jobs of failed pairs)",
        )
    return len(failed)


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
@click.argument("overrides", nargs=-1, metavar="[KEY=VALUE]...")
@click.option("--jobs", "-j", type=int, help="Parallel workers (overrides the config; -1 all).")
@click.option(
    "--force", is_flag=True,
    help="Recompute every job, even finished ones; replaces another config's run in the folder.",
)  # fmt: skip
@click.option(
    "--update", is_flag=True,
    help="Make a folder holding another config's run this config's run, keeping every result "
    "whose job is unchanged (after editing a parameter, say).",
)  # fmt: skip
@click.option(
    "--retry-failed", is_flag=True,
    help="Run jobs that failed before again (a plain rerun only reports them).",
)  # fmt: skip
@click.option(
    "--timeout", type=click.FloatRange(min=0, min_open=True), metavar="SECONDS",
    help="A job running longer fails (overrides the config's job_timeout_s).",
)  # fmt: skip
@click.option("--no-progress", is_flag=True, help="Hide the progress bars.")
@click.option("--no-report", is_flag=True, help="Skip the PDF report (tables are still written).")
@click.option(
    "--backend", type=click.Choice(["local", "dask"]), default="local", show_default=True,
    help="local: isolated workers on this machine; dask: a Dask cluster (see --scheduler).",
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
    overrides: tuple[str, ...],
    jobs: int | None,
    force: bool,
    update: bool,
    retry_failed: bool,
    timeout: float | None,
    no_progress: bool,
    no_report: bool,
    backend: str,
    scheduler: str | None,
    shard: tuple[int, int] | None,
    check: bool,
) -> None:
    """Run the benchmark described by CONFIG_FILE; resumes an interrupted run.

    KEY=VALUE settings override the config's (a dotted key path, list items by index, a YAML
    value): methods.0.params.ratio=0.7 goals=all output=runs/other. The resolved config in the
    run folder shows the values used; environment.json lists the overrides.

    A job that fails (raises, crashes, hangs past the timeout, runs out of memory) is recorded
    in the run folder and reported; a plain rerun reports it again, --retry-failed reruns it.
    """
    check_run_space()
    from homebench.api import run_grid
    from homebench.config import grid_config, kind_of
    from homebench.errors import ConfigError
    from homebench.experiments.config_files import validated_config
    from homebench.yamlio import read_yaml

    document = read_yaml(config_file, "config", overrides)  # the one read of the file
    kind = kind_of(document.data)
    if kind != "grid":
        grid_only = backend != "local" or shard is not None or check or retry_failed or update
        if grid_only:
            raise ConfigError(
                "--backend dask, --shard, --check, --retry-failed and --update are for grid "
                f"runs, not {kind} runs"
            )
        if timeout is not None:  # the config's key: the resolved config shows the value used
            document = document.overridden([f"job_timeout_s={timeout!r}"])
        config = validated_config(document)
        _run_experiment(kind, config, config_file, jobs, force, no_progress, no_report)
        return
    done = run_grid(
        config_file,
        overrides,
        config=grid_config(document),
        jobs=jobs,
        timeout_s=timeout,
        backend=backend,
        scheduler=scheduler,
        shard=shard,
        retry_failed=retry_failed,
        force=force,
        update=update,
        show_progress=not no_progress,
    )
    config, outcome, tables, written = done.config, done.outcome, done.tables, done.files
    for warning in outcome.warnings:
        _say("warning: ", warning)
    for note in outcome.notes:
        _say("note: ", note)
    if not tables.summary.empty:
        click.echo(_format_summary(tables, config))
    failed_jobs = sum(failure.kind == "home" for failure in outcome.failures)
    failed = f", {failed_jobs} failed" if failed_jobs else ""
    click.echo(
        f"{outcome.computed} job(s) computed, {outcome.reused} reused{failed}; "
        f"tables in {written[0].parent}"
    )
    if outcome.pending:
        click.echo(
            f"{outcome.pending} job(s) of the plan have no result here yet (other shards?): "
            "their rows are not in the tables; rerun or `homebench report` once all job files "
            "are in place"
        )
    if not no_report and not tables.summary.empty:
        from homebench.report.document import write_report

        report = write_report(outcome.run_dir, progress=not no_progress, tables=tables)
        click.echo(f"report: {report.files[-1]}")
    failed_pairs = _report_failures(outcome, tables.pairs)
    if outcome.failures or failed_pairs:
        sys.exit(EXIT_CRASH)
    if check:
        from homebench.evaluation.checks import failed_checks

        if not config.checks:
            raise ConfigError(f"{config_file}: --check needs a 'checks' section")
        reasons = failed_checks(tables.summary, config.checks)
        for reason in reasons:
            _say("check failed: ", reason)
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
    "--max-goals", type=click.IntRange(min=0), default=DEFAULT_MAX_GOALS, show_default=True,
    help="Goals per condition drawn as vector fields and AE maps (the appendix); 0: every goal.",
)  # fmt: skip
@click.option("--no-progress", is_flag=True, help="Hide the progress bar over the figures.")
def report(
    run_dir: Path,
    formats: tuple[str, ...],
    out: Path | None,
    max_goals: int | None,
    no_progress: bool,
) -> None:
    """Write the tables, figures and PDF report of the run in RUN_DIR."""
    from homebench.report.document import write_report

    outcome = write_report(run_dir, formats, out, max_goals or None, progress=not no_progress)
    for warning in outcome.warnings:
        _say("warning: ", f"missing job result {warning}")
    for path in outcome.files:
        click.echo(str(path))


_LABEL = click.option(
    "--label", "labels", multiple=True, metavar="NAME",
    help="Name of a run, in the runs' order (repeatable; default: the folders' names).",
)  # fmt: skip
_TABLE_OUT = click.option(
    "--out", type=click.Path(path_type=Path),
    help="Also write the table to this file: .csv, .md or .tex.",
)  # fmt: skip


@main.command()
@click.argument("run_dirs", nargs=-1, required=True, type=click.Path(path_type=Path))
@_LABEL
@click.option(
    "--fail-if", "fail_if", multiple=True, metavar="EXPR",
    help="Exit 3 when a run's change to the first meets EXPR in any cell (repeatable), e.g. "
    "'ahc < -0.02', 'mean_ae_deg > 2', 'home_ms > 1.5' (times: ratios).",
)  # fmt: skip
@_TABLE_OUT
def compare(
    run_dirs: tuple[Path, ...], labels: tuple[str, ...], fail_if: tuple[str, ...], out: Path | None
) -> None:
    """Compare runs with the first: what differs in their configs and environments, then per
    condition and method the change in mean AE, AHC and RR with its 95 % interval and
    Holm-corrected p-value (paired where the runs share goals) and the time ratios."""
    from homebench.report.across_runs.compare import (
        Threshold,
        compare_runs,
        renderer_for,
        write_view_file,
    )
    from homebench.report.tables import to_markdown

    thresholds = [Threshold.parse(text) for text in fail_if]
    if out is not None:
        renderer_for(out)
    comparison = compare_runs(run_dirs, labels)
    click.echo(comparison.differences_text() + "\n")
    for warning in comparison.warnings:
        _say("warning: ", warning)
    click.echo(to_markdown(comparison.view()))
    if out is not None:
        click.echo(str(write_view_file(comparison.view(), out)))
    reasons = [reason for t in thresholds for reason in t.violations(comparison.table)]
    for reason in reasons:
        _say("check failed: ", reason)
    if reasons:
        sys.exit(EXIT_CHECK)
    if thresholds:
        click.echo(f"all {len(thresholds)} --fail-if threshold(s) passed")


@main.command()
@click.argument("run_dirs", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option(
    "--metric",
    type=click.Choice(["ahc", "ahc_missing90", "no_estimate_share", "rr", "mean_ae_deg"]),
    default="ahc", show_default=True,
    help="The metric ranked (ahc_missing90: the AHC with a missing estimate as 90 deg).",
)  # fmt: skip
@_LABEL
@_TABLE_OUT
@click.option(
    "--html", "html_file", type=click.Path(path_type=Path),
    help="Also write an HTML page with the table and a link to each run's report.",
)  # fmt: skip
def leaderboard(
    run_dirs: tuple[Path, ...],
    metric: str,
    labels: tuple[str, ...],
    out: Path | None,
    html_file: Path | None,
) -> None:
    """One table of the methods of RUN_DIRS under each condition: the metric with its 95 %
    interval, the best of each column marked *; where a method gave no estimate for some
    pairs, an AHC cell adds the other AHC and the share without an estimate, a mean AE cell
    the share."""
    from homebench.report.across_runs.compare import renderer_for, write_view_file
    from homebench.report.across_runs.leaderboard import leaderboard as make_leaderboard
    from homebench.report.across_runs.leaderboard import write_index
    from homebench.report.tables import to_markdown

    if out is not None:
        renderer_for(out)
    board = make_leaderboard(run_dirs, labels, metric)
    for warning in board.warnings:
        _say("warning: ", warning)
    click.echo(to_markdown(board.view))
    if out is not None:
        click.echo(str(write_view_file(board.view, out)))
    if html_file is not None:
        click.echo(str(write_index(board, html_file)))


class _FindingsCommand(click.Command):
    """The findings command, whose help ends with what each finding needs, generated from
    the findings' own definitions when the help is shown."""

    def format_epilog(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        from homebench.report.across_runs.findings import ROLE_DEFAULTS, requirements

        formatter.write_paragraph()
        formatter.write_text("What each finding needs (roles; --role ROLE=VALUE names them):")
        with formatter.indentation():
            for line in requirements():
                formatter.write_text(line)
        formatter.write_paragraph()
        defaults = ", ".join(f"{role}={value}" for role, value in ROLE_DEFAULTS.items())
        formatter.write_text(f"Roles by default: {defaults}.")


def _named(values: tuple[str, ...], option: str) -> dict[str, str]:
    """``NAME=VALUE`` option values as a dict; ConfigError naming a malformed one."""
    from homebench.errors import ConfigError

    found = {}
    for text in values:
        name, sep, value = text.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise ConfigError(f"{option} {text!r}: expected NAME=VALUE")
        found[name.strip()] = value.strip()
    return found


@main.command(cls=_FindingsCommand)
@click.argument("run_dirs", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option(
    "--alpha",
    type=click.FloatRange(0, 1, min_open=True, max_open=True),
    default=0.05,
    show_default=True,
    help="Significance level of the verdicts.",
)
@click.option(
    "--role",
    "roles",
    multiple=True,
    metavar="ROLE=VALUE",
    help="A finding's method by label or method name (P=sift, W=warping, PN=sift-pn, "
    "KLT=klt-sector) or condition (original=a-a, arboreal=a-b, day=a-c); repeatable.",
)
@click.option(
    "--pool",
    type=click.Choice(["style", "all"]),
    help="Pool runs into places: by world style (a run's generated world's, or each swept "
    "style), or all into one. Default: each swept style a place, each other run its own.",
)
@click.option(
    "--place",
    "places",
    multiple=True,
    metavar="RUN=NAME",
    help="Name the place of a run (its label: the folder's name); runs of one name are "
    "pooled, goals of every run the units; repeatable.",
)
@click.option("--out", type=click.Path(path_type=Path),
              help="Folder for findings.csv, .md and .tex.")  # fmt: skip
def findings(
    run_dirs: tuple[Path, ...],
    alpha: float,
    roles: tuple[str, ...],
    pool: Literal["style", "all"] | None,
    places: tuple[str, ...],
    out: Path | None,
) -> None:
    """Test the papers' findings and the runs' own claims on RUN_DIRS: seed 001's findings
    on grid runs, seed 000's on route runs, and each run config's claims (a closed-loop
    run's alone: no paper finding is about closed loops); each with its effect, 95 %
    interval, Holm-corrected p, verdict and the goals (or trials) it rests on, per place.
    Findings the runs cannot test are listed with the reason; exit 2 when none could be."""
    from homebench.errors import DataError
    from homebench.report.across_runs.findings import (
        findings_of_runs,
        findings_view,
        untestable_view,
    )
    from homebench.report.tables import to_markdown, write_views

    chosen = _named(roles, "--role")
    found = findings_of_runs(run_dirs, chosen, alpha, pool, _named(places, "--place"))
    for warning in found.warnings:
        _say("warning: ", warning)
    views = []
    if not found.table.empty:
        views.append(findings_view(found.table, alpha, found.units))
        click.echo(to_markdown(views[0]))
    if not found.untestable.empty:
        views.append(untestable_view(found.untestable))
        click.echo(to_markdown(views[-1]))
    if found.table.empty:
        raise DataError("findings: none of the findings could be tested on these runs (see above)")
    if out is not None:
        for path in write_views(views, out):
            click.echo(str(path))
