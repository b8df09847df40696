"""`homebench run` end to end on a user-made database (the analytic arena), as a user runs it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from conftest import arena_config, write_arena_database

from homebench.cli import main

TIME_COLUMNS = ["home_ms", "describe_ms", "goal_describe_ms"]


def _config(tmp_path: Path, manifest: Path, **changes: object) -> Path:
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(arena_config(tmp_path, manifest, **changes)))
    return path


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, ["run", *args, "--no-progress", "--no-report"])
    return result.exit_code, result.stdout, result.stderr


#: What may differ between runs of one config: times measured in the workers, and nothing else.
TIMING = {
    "pairs": {"describe_ms", "home_ms", "goal_describe_ms"},
    "summary": {"describe_ms", "home_ms"},
    "goals": set(),
    "ahc": set(),
}


def _tables(run_dir: Path) -> dict[str, pd.DataFrame]:
    """The run's tables without their timing columns (which must be exactly ``TIMING``)."""
    tables = {}
    for name, timing in TIMING.items():
        frame = pd.read_csv(run_dir / "tables" / f"{name}.csv")
        assert {c for c in frame.columns if c.endswith("_ms")} == timing, name
        tables[name] = frame.drop(columns=sorted(timing))
    return tables


def _assert_same_tables(a: Path, b: Path) -> None:
    """Equal tables, column by column, but for the timing columns."""
    expected, found = _tables(a), _tables(b)
    for name, table in expected.items():
        assert list(found[name].columns) == list(table.columns), name
        for column in table.columns:
            pd.testing.assert_series_equal(
                found[name][column], table[column], obj=f"{name}.{column}"
            )


def test_run_writes_tables_with_sensible_metrics(tmp_path: Path, arena_manifest: Path) -> None:
    code, out, err = _run(str(_config(tmp_path, arena_manifest)))
    assert code == 0, err
    assert "mean AE [deg]" in out and "tables in" in out
    run_dir = tmp_path / "run"
    pairs = pd.read_csv(run_dir / "tables" / "pairs.csv")
    assert len(pairs) == 2 * 2 * 19  # methods x goals x (20 positions - the goal)
    assert set(pairs["method"]) == {"warping", "warping-coarse"}
    assert (pairs["distance_m"] > 0).all()
    times = pairs[TIME_COLUMNS]  # a worker's first call of a method has none: one-off costs
    assert ((times >= 0) | times.isna()).all().all() and times.notna().mean().min() > 0.9
    summary = pd.read_csv(run_dir / "tables" / "summary.csv")
    # the arena is close to warping's equal-distance assumption: errors are small
    assert (summary["mean_ae_deg"] < 30).all()
    assert (summary["ahc"] > 0.85).all()
    assert (summary["rr"] > 0.8).all()
    for name in ("config.resolved.json", "environment.json", "plan.json"):
        assert (run_dir / name).is_file()


def test_a_run_reads_its_results_and_compares_its_methods_once(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The tables, the printed summary and the report share one reading of the job files and
    one set of paired comparisons (each took a quick start's main process 0.1-0.3 s)."""
    from homebench.analysis import comparisons
    from homebench.evaluation import results

    calls = {"load_pairs": 0, "comparison_table": 0}

    def counted(module: object, name: str) -> None:
        original = getattr(module, name)

        def count(*args: object, **kwargs: object) -> object:
            calls[name] += 1
            return original(*args, **kwargs)

        monkeypatch.setattr(module, name, count)

    counted(results, "load_pairs")
    counted(comparisons, "comparison_table")
    path = _config(tmp_path, arena_manifest)
    result = CliRunner().invoke(main, ["run", str(path), "--no-progress"])
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "run" / "report" / "report.pdf").is_file()
    assert calls == {"load_pairs": 1, "comparison_table": 1}


def test_a_fresh_run_starts_its_worker_server_before_planning_a_finished_one_none(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The server imports while the run plans (its data exist: nothing to generate); a rerun
    whose jobs are all done starts no server at all."""
    from homebench.evaluation import isolation, runner

    events: list[str] = []
    start_server, make_plan = isolation.WorkerPool.start_server, runner.make_plan

    def starting(pool: isolation.WorkerPool) -> None:
        events.append("start")
        start_server(pool)

    def planning(*args: object, **kwargs: object) -> object:
        events.append("plan")
        return make_plan(*args, **kwargs)

    monkeypatch.setattr(isolation.WorkerPool, "start_server", starting)
    monkeypatch.setattr(runner, "make_plan", planning)
    config = _config(tmp_path, arena_manifest)
    assert _run(str(config))[0] == 0
    assert events[:2] == ["start", "plan"]
    events.clear()
    code, out, _ = _run(str(config))
    assert code == 0 and "0 job(s) computed, 4 reused" in out
    assert events == ["plan"]


def test_tables_are_equal_across_workers_backends_and_shards(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """--jobs 1, --jobs 2, a Dask cluster and two shards give the same tables, column by column,
    except the timing columns."""
    import distributed  # the test extra installs it: a missing package must fail, not skip

    folders = {name: tmp_path / name for name in ("one", "two", "dask", "sharded")}
    configs = {}
    for name, folder in folders.items():
        folder.mkdir()
        configs[name] = str(_config(folder, arena_manifest))
    assert _run(configs["one"], "--jobs", "1")[0] == 0
    assert _run(configs["two"], "--jobs", "2")[0] == 0
    code, out, _ = _run(configs["sharded"], "--shard", "1/2")
    assert code == 0 and "have no result here yet (other shards?)" in out
    assert _run(configs["sharded"], "--shard", "2/2")[0] == 0
    code, _, err = _run(configs["sharded"], "--shard", "4/3")
    assert code == 2 and "need 1 <= i <= n" in err
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:  # fmt: skip
        code, _, err = _run(
            configs["dask"], "--backend", "dask", "--scheduler", cluster.scheduler_address
        )
    assert code == 0, err
    for name in ("two", "dask", "sharded"):
        _assert_same_tables(folders["one"] / "run", folders[name] / "run")


def test_rerun_recomputes_only_what_is_missing(tmp_path: Path, arena_manifest: Path) -> None:
    config = _config(tmp_path, arena_manifest)
    assert _run(str(config))[0] == 0
    jobs = sorted((tmp_path / "run" / "jobs").glob("*.json"))
    assert len(jobs) == 4
    jobs[0].unlink()
    code, out, _ = _run(str(config))
    assert code == 0 and "1 job(s) computed, 3 reused" in out
    # a changed parameter is another config: refused, unless --force replaces the run
    changed = _config(
        tmp_path,
        arena_manifest,
        methods=[
            {"method": "warping"},
            {"method": "warping", "label": "warping-coarse", "params": {"n_rho": 6}},
        ],
    )
    code, out, err = _run(str(changed))
    assert code == 2 and "holds the run of another config" in err
    assert "--update" in err and "--force" in err
    # --update adopts the folder: only the changed entry's jobs run (keys say what changed)
    code, out, _ = _run(str(changed), "--update")
    assert code == 0 and "2 job(s) computed, 2 reused" in out
    code, out, _ = _run(str(changed), "--force")
    assert code == 0 and "4 job(s) computed, 0 reused" in out


def _settled_count(jobs_dir: Path, quiet_s: float = 1.0) -> int:
    """The job files in ``jobs_dir`` once none has appeared for ``quiet_s`` seconds: a process
    being killed may still finish the rename it is in."""
    count, since = -1, time.monotonic()
    while True:
        now = len(list(jobs_dir.glob("*.json")))
        if now != count:
            count, since = now, time.monotonic()
        elif time.monotonic() - since >= quiet_s:
            return count
        time.sleep(0.05)


def test_killed_run_resumes_to_the_same_tables(tmp_path: Path, arena_manifest: Path) -> None:
    reference, killed = tmp_path / "reference", tmp_path / "killed"
    reference.mkdir(), killed.mkdir()
    changes = {"goals": "all", "methods": [{"method": "warping"}]}
    assert _run(str(_config(reference, arena_manifest, **changes)))[0] == 0
    config = _config(killed, arena_manifest, **changes)
    command = [
        sys.executable,
        "-m",
        "homebench",
        "run",
        str(config),
        "--jobs",
        "1",
        "--no-progress",
        "--no-report",
    ]
    # its own session, so that the kill reaches the run, its worker server and its worker at once
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )
    jobs_dir = killed / "run" / "jobs"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(jobs_dir.glob("*.json"))) < 3:
        if process.poll() is not None:
            break
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    finished = _settled_count(jobs_dir)
    assert 0 < finished < 20, "the run should have been killed half-way"
    code, out, err = _run(str(config))
    assert code == 0, err
    assert f"{20 - finished} job(s) computed, {finished} reused" in out
    _assert_same_tables(reference / "run", killed / "run")


def test_rotated_current_views_keep_the_home_direction(
    tmp_path: Path, arena_manifest: Path
) -> None:
    config = _config(tmp_path, arena_manifest, rotate_current={"enabled": True, "seed": 3})
    code, _, err = _run(str(config))
    assert code == 0, err
    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    assert (pairs["rotation_rad"] != 0).mean() > 0.9
    summary = pd.read_csv(tmp_path / "run" / "tables" / "summary.csv")
    assert (summary["mean_ae_deg"] < 30).all()


def test_route_method_gets_the_views_between_goal_and_current(
    tmp_path: Path, arena_manifest: Path
) -> None:
    config = _config(tmp_path, arena_manifest, methods=[{"method": "klt-sector"}])
    code, _, err = _run(str(config))
    assert code == 0, err
    pairs = pd.read_csv(tmp_path / "run" / "tables" / "pairs.csv")
    far = pairs[pairs["distance_m"] > 0.5]
    assert (far["route_views"] > 0).all()
    assert (pairs["distance_m"] < 0.45).sum() > 0
    assert (pairs.loc[pairs["distance_m"] < 0.45, "route_views"] == 0).all()
    assert pairs["ae_deg"].mean() < 15


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"goals": [[7, 1]]}, "goals.0: (7, 1) is outside the 4 x 5 grid"),
        ({"databases": {"arena": "no-such-db"}}, "unknown database 'no-such-db'"),
        ({"jobs": 0}, "jobs: jobs must be a positive number"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, arena_manifest: Path, changes: dict, message: str
) -> None:
    code, out, err = _run(str(_config(tmp_path, arena_manifest, **changes)))
    assert code == 2
    assert message in err
    assert "Traceback" not in err
    assert not (tmp_path / "run" / "jobs").exists()


def test_missing_image_names_the_position(tmp_path: Path, arena_manifest: Path) -> None:
    manifest = write_arena_database(tmp_path / "broken")
    (tmp_path / "broken" / "pano" / "p2-3.png").unlink()
    code, _, err = _run(str(_config(tmp_path, manifest)))
    assert code == 2
    assert "(2,3)" in err


def test_check_passes_fails_with_exit_3_and_names_each_threshold(
    tmp_path: Path, arena_manifest: Path
) -> None:
    good = {"warping": {"ahc_min": 0.8, "rr_min": 0.8}}
    code, out, err = _run(str(_config(tmp_path, arena_manifest, checks=good)), "--check")
    assert code == 0, err
    assert "all 1 method check(s) passed" in out
    bad = {"warping": {"mean_ae_max_deg": 0.001}, "warping-coarse": {"rr_min": 1.0, "ahc_min": 1}}
    code, _, err = _run(str(_config(tmp_path, arena_manifest, checks=bad)), "--check")
    assert code == 3
    failed = [line for line in err.splitlines() if line.startswith("homebench: check failed:")]
    assert any("warping in arena-arena: mean_ae_deg" in line for line in failed)
    assert any("warping-coarse in arena-arena: ahc" in line for line in failed)
    code, _, err = _run(str(_config(tmp_path, arena_manifest, checks={"sift": {}})), "--check")
    assert code == 2 and "checks: no method entry labelled 'sift'" in err


def test_parquet_pairs_table_holds_the_csv_rows(tmp_path: Path, arena_manifest: Path) -> None:
    csv_dir, parquet_dir = tmp_path / "csv", tmp_path / "parquet"
    csv_dir.mkdir(), parquet_dir.mkdir()
    assert _run(str(_config(csv_dir, arena_manifest)))[0] == 0
    assert _run(str(_config(parquet_dir, arena_manifest, table_format="parquet")))[0] == 0
    from_csv = pd.read_csv(csv_dir / "run" / "tables" / "pairs.csv")
    from_parquet = pd.read_parquet(parquet_dir / "run" / "tables" / "pairs.parquet")
    assert not (parquet_dir / "run" / "tables" / "pairs.csv").exists()
    for empty in ("error", "style"):  # no failures, no swept style
        assert from_csv[empty].isna().all() and from_parquet[empty].isna().all()
    columns = [c for c in from_csv.columns if not c.endswith("_ms") and c not in ("error", "style")]
    seed_as_float = {"seed": "float64"}  # no sweep: all missing (Int64 <NA> vs CSV's NaN)
    pd.testing.assert_frame_equal(
        from_parquet[columns].astype(seed_as_float).reset_index(drop=True),
        from_csv[columns].astype(seed_as_float),
        check_dtype=False,
        rtol=1e-5,
    )


def test_a_torn_job_file_is_never_read_back(tmp_path: Path, arena_manifest: Path) -> None:
    """What a SIGKILL mid-write could leave — a half-written result, a stray temporary file —
    is recomputed or ignored, and the tables come out as from a clean run."""
    reference, torn = tmp_path / "reference", tmp_path / "torn"
    reference.mkdir(), torn.mkdir()
    assert _run(str(_config(reference, arena_manifest)))[0] == 0
    config = _config(torn, arena_manifest)
    assert _run(str(config))[0] == 0
    jobs = sorted((torn / "run" / "jobs").glob("*.json"))
    text = jobs[0].read_text()
    jobs[0].write_text(text[: len(text) // 2])  # a torn write under the final name
    (jobs[1].parent / f".{jobs[1].name}.k3j2.tmp").write_text(text[:100])  # a stray temp file
    code, out, err = _run(str(config))
    assert code == 0, err
    assert "1 job(s) computed, 3 reused" in out
    _assert_same_tables(reference / "run", torn / "run")


@pytest.mark.parametrize("n_jobs", [1, 2, 3, 4, 7])
def test_shards_split_any_plan_into_parts_of_equal_size(n_jobs: int) -> None:
    """Every key in exactly one of N shards, sizes differing by at most one, whatever the keys
    (a split by hash could give one shard every job of a small plan)."""
    from homebench.evaluation.executors import Execution

    keys = [f"{k:02x}" + "0" * 14 for k in range(n_jobs)]  # every key's hash is even
    for count in (2, 3):
        parts = [Execution(shard=(i, count)).shard_keys(reversed(keys)) for i in (1, 2, 3)[:count]]
        assert set().union(*parts) == set(keys)
        assert sum(len(p) for p in parts) == n_jobs
        assert max(map(len, parts)) - min(map(len, parts)) <= 1
    assert Execution().shard_keys(keys) == set(keys)
