"""Hostile or careless input met as a user meets it: one line naming the file or key, exit 2,
nothing half-written (issue 12, "Bounded, validated input")."""

from __future__ import annotations

import errno
import os
import shutil
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner, Result
from conftest import arena_config, run_config
from mounts import tmpfs

from homebench.cli import main
from homebench.data.manifest import load_manifest
from homebench.errors import ConfigError, DataError

MANIFEST = """\
schema: 1
name: hostile
grid: {{shape: [3, 2], spacing: 0.25}}
heading_deg: 0
images:
  unfolded:
    folder: pano
    pattern: {pattern}
    size: [40, 12]
    panorama: {{elevation_top_deg: 30, elevation_bottom_deg: -30}}
"""


def _invoke(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


def _one_error_line(err: str) -> str:
    """The single "homebench: error:" line of ``err`` (fails if there are others)."""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("homebench: error: "), err
    return lines[0]


def _manifest(folder: Path, pattern: str) -> Path:
    (folder / "pano").mkdir(parents=True, exist_ok=True)
    path = folder / "manifest.yaml"
    path.write_text(MANIFEST.format(pattern=f'"{pattern}"'), encoding="utf-8")
    return path


# ------------------------------------------------------------------ manifest patterns


@pytest.mark.parametrize(
    "pattern",
    [
        "{x!s:.0}{y!s:.0}/etc/passwd",  # a conversion and a precision: an absolute path
        "{x!s:.>2.0}/{y!s:.>2.0}/etc/passwd",  # '.' fill: ../../etc/passwd
        "{x:/>3}_{y}.png",  # a '/' fill character
        "{x:012d}_{y}.png",  # wider than the cap
        "{x:+d}_{y}.png",
        "{x:x}_{y}.png",
        "{x:_}_{y}.png",
        "{x:{y}}_{y}.png",  # a nested field
        "{x}_{y}.{ext:.1}",
        "{x}{y}/..",  # a '..' component
        "{x}//{y}.png",  # an empty component
        "{x}_{y}\\t.png",  # a control character
    ],
)
def test_a_pattern_that_could_leave_the_folder_is_refused(tmp_path: Path, pattern: str) -> None:
    manifest = _manifest(tmp_path, pattern)
    code, _, err = _invoke("data", "verify", str(manifest))
    assert code == 2
    line = _one_error_line(err)
    assert str(manifest) in line and "images.unfolded.pattern" in line


@pytest.mark.parametrize(
    ("pattern", "name"),
    [
        ("{x}_{y}.png", "2_1.png"),
        ("{x:d}-{y:d}.png", "2-1.png"),
        ("img-{x:03d}-{y:03d}.png", "img-002-001.png"),
        ("{x:3d}_{y:3}.png", "  2_  1.png"),
        ("row{y}/{x:02}.{ext}", "row1/02.png"),
        ("{x}/{x}_{y}.png", "2/2_1.png"),
    ],
)
def test_plain_integer_fields_with_a_width_are_allowed(
    tmp_path: Path, pattern: str, name: str
) -> None:
    section = load_manifest(_manifest(tmp_path, pattern)).section("unfolded")
    assert section.file_names(2, 1) == [name]
    assert section.parse_name(name) == (2, 1)


def test_every_formatted_name_is_checked_to_stay_inside(tmp_path: Path) -> None:
    """Even a section built without validation cannot name a file outside its folder."""
    good = load_manifest(_manifest(tmp_path, "{x}_{y}.png")).section("unfolded")
    bad = good.model_copy(update={"pattern": "{x!s:.>2.0}/{y!s:.>2.0}/etc/passwd"})
    with pytest.raises(DataError, match=r"'\.\./\.\./etc/passwd' .*outside"):
        bad.file_names(0, 0)


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("[3, 2]", "[1000000, 1000000]", r"grid\.shape: .*at most 1,000,000 positions"),
        ("[40, 12]", "[30000, 30000]", r"images\.unfolded\.size: .*more than .* pixels"),
    ],
)
def test_a_huge_grid_or_image_size_is_refused(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    path = _manifest(tmp_path, "{x}_{y}.png")
    path.write_text(path.read_text().replace(old, new))
    with pytest.raises(ConfigError, match=expected):
        load_manifest(path)


@pytest.mark.parametrize(
    ("config", "override", "key"),
    [
        ("klt_route.yaml", "routes.0.waypoints.1=[.nan, 2.0]", "routes[0].waypoints[1][0]"),
        ("klt_route.yaml", "routes.0.heading_deg=.inf", "routes[0].heading_deg"),
        ("closed_loop.yaml", "goals.0={at: [1.0, .nan]}", "goals[0].at[1]"),
        ("closed_loop.yaml", "starts.region=[0.2, 1.4, .inf, 3.4]", "region[2]"),
    ],
)
def test_a_point_that_is_not_a_number_is_refused(
    tmp_path: Path, config: str, override: str, key: str
) -> None:
    """A NaN waypoint was "cannot convert float NaN to integer", exit 1."""
    path = Path(__file__).resolve().parent.parent / "configs" / config
    code, _, err = _invoke(
        "run", str(path), override, f"output={tmp_path / 'run'}", "--no-progress", "--no-report"
    )
    assert code == 2
    line = _one_error_line(err)
    assert f"{key}: Input should be a finite number" in line
    assert not (tmp_path / "run").exists()


# ------------------------------------------------------------------ run folders and image folders


@pytest.fixture
def database(tmp_path: Path, arena_manifest: Path) -> Path:
    """A private copy of the arena database (4 x 5 unfolded images in pano/); its manifest."""
    shutil.copytree(arena_manifest.parent, tmp_path / "db")
    return tmp_path / "db" / "manifest.yaml"


def _run(tmp_path: Path, manifest: Path, *options: str, **changes: object) -> Result:
    return run_config(tmp_path, arena_config(tmp_path, manifest, **changes), *options)


def _no_jobs_ran(run_dir: Path) -> bool:
    return not any((run_dir / folder).exists() for folder in ("jobs", "features", "tables"))


@pytest.mark.parametrize("timeout", ["1e12", "inf"])
def test_a_timeout_beyond_what_the_system_waits_is_no_crash(
    tmp_path: Path, database: Path, timeout: str
) -> None:
    """It crashed: "OverflowError: timestamp too large to convert to C _PyTime_t"."""
    result = _run(tmp_path, database, "--timeout", timeout, methods=[{"method": "warping"}])
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("output", ["run", "run/deeper"])
def test_a_run_folder_that_is_a_file(tmp_path: Path, database: Path, output: str) -> None:
    """Said as it is, not as the lock file it could not create inside."""
    (tmp_path / "run").write_text("my notes\n")
    result = _run(tmp_path, database, output=str(tmp_path / output))
    assert result.exit_code == 2
    line = _one_error_line(result.stderr)
    assert line == f"homebench: error: {tmp_path / 'run'}: is a file, not a folder"
    assert (tmp_path / "run").read_text() == "my notes\n"


@pytest.fixture
def read_only(tmp_path: Path) -> Iterator[Path]:
    """A folder in which nothing can be created: a read-only file system (a tmpfs mounted
    read-only), or, where none can be mounted, a folder without write permission (which root
    ignores: then the test skips)."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    with tmpfs(folder, "ro,size=64k") as problem:
        if not problem:
            yield folder
            return
    if os.geteuid() == 0:
        pytest.skip(problem)
    folder.chmod(0o555)
    yield folder
    folder.chmod(0o755)


def test_a_run_folder_on_a_read_only_file_system(
    tmp_path: Path, database: Path, read_only: Path
) -> None:
    result = _run(tmp_path, database, output=str(read_only / "run"))
    assert result.exit_code == 2
    assert str(read_only / "run") in _one_error_line(result.stderr)
    assert list(read_only.iterdir()) == []


def _symlink_loop(folder: Path) -> None:
    shutil.rmtree(folder)
    folder.symlink_to(folder.with_name("loop"))
    folder.with_name("loop").symlink_to(folder)


@pytest.mark.parametrize(
    "command",
    [
        lambda manifest, tmp_path: ["data", "verify", str(manifest)],
        lambda manifest, tmp_path: ["data", "show", str(manifest), "--out", str(tmp_path)],
    ],
    ids=["verify", "show"],
)
def test_an_image_folder_that_is_a_symlink_loop(
    tmp_path: Path, database: Path, command: Callable[[Path, Path], list[str]]
) -> None:
    _symlink_loop(database.parent / "pano")
    code, _, err = _invoke(*command(database, tmp_path / "out"))
    assert code == 2
    line = _one_error_line(err)
    assert str(database.parent / "pano") in line and "symbolic links" in line
    assert not (tmp_path / "out").exists()


def test_a_run_over_a_symlink_loop(tmp_path: Path, database: Path) -> None:
    _symlink_loop(database.parent / "pano")
    result = _run(tmp_path, database)
    assert result.exit_code == 2
    assert "symbolic links" in _one_error_line(result.stderr)
    assert _no_jobs_ran(tmp_path / "run")


def _verify_or_run(command: str, tmp_path: Path, database: Path) -> tuple[int, str]:
    """``data verify`` of ``database`` or a run on it (``command``): exit code and stderr."""
    if command == "verify":
        code, _, err = _invoke("data", "verify", str(database))
        return code, err
    result = _run(tmp_path, database)
    return result.exit_code, result.stderr


@pytest.mark.parametrize("command", ["verify", "run"])
def test_an_image_that_is_a_symlink_loop_is_named(
    tmp_path: Path, database: Path, command: str
) -> None:
    """It was "no image for grid position (2,3)"."""
    victim = database.parent / "pano" / "p2-3.png"
    victim.unlink()
    victim.symlink_to(victim.name)
    code, err = _verify_or_run(command, tmp_path, database)
    assert code == 2
    assert _one_error_line(err) == (
        f"homebench: error: {victim}: cannot open the image (Too many levels of symbolic links)"
    )


@pytest.mark.parametrize(
    ("kind", "make"), [("a folder", Path.mkdir), ("a FIFO", os.mkfifo)], ids=["folder", "fifo"]
)
@pytest.mark.parametrize("command", ["verify", "run"])
def test_an_image_that_is_no_file_is_called_what_it_is(
    tmp_path: Path, database: Path, command: str, kind: str, make: Callable[[Path], None]
) -> None:
    """It was "no image for grid position (2,3)"."""
    victim = database.parent / "pano" / "p2-3.png"
    victim.unlink()
    make(victim)
    code, err = _verify_or_run(command, tmp_path, database)
    assert code == 2
    assert _one_error_line(err) == f"homebench: error: {victim}: the image is {kind}, not a file"


@pytest.mark.parametrize("command", [["run"], ["report"], ["data", "verify"]])
def test_control_characters_of_a_file_name_are_escaped(tmp_path: Path, command: list[str]) -> None:
    """They were echoed raw: a name could clear the screen, ring the bell, start a line."""
    name = tmp_path / "x\x1b[2J\x07\x9b\u2028y.yaml"
    code, _, err = _invoke(*command, str(name))
    assert code == 2
    line = _one_error_line(err)
    assert "x\\x1b[2J\\x07\\x9b\\u2028y.yaml" in line, line
    assert line.isprintable(), line


def test_an_unreachable_dask_scheduler_is_one_line(tmp_path: Path, database: Path) -> None:
    import distributed  # noqa: F401  (the test extra installs it: a missing package must fail)

    start = time.monotonic()
    result = _run(tmp_path, database, "--backend", "dask", "--scheduler", "tcp://127.0.0.1:1")
    assert time.monotonic() - start < 60
    assert result.exit_code == 2
    assert "tcp://127.0.0.1:1" in _one_error_line(result.stderr)
    assert _no_jobs_ran(tmp_path / "run")


@pytest.mark.parametrize("address", ["not a url", "tcp://", "tcp://host:port"])
def test_a_scheduler_address_that_is_none_is_a_usage_error(
    tmp_path: Path, database: Path, address: str
) -> None:
    result = _run(tmp_path, database, "--backend", "dask", "--scheduler", address)
    assert result.exit_code == 2
    line = _one_error_line(result.stderr)
    assert f"--scheduler {address!r}: not an address of a Dask scheduler" in line
    assert not (tmp_path / "run").exists()


def test_an_os_error_anywhere_is_one_line_naming_the_file(monkeypatch: pytest.MonkeyPatch) -> None:
    from homebench.data import catalog

    def broken_disk() -> list:
        raise OSError(errno.EIO, os.strerror(errno.EIO), "/data/manifests/x.yaml")

    monkeypatch.setattr(catalog, "list_databases", broken_disk)
    code, _, err = _invoke("data", "list")
    assert code == 2
    assert _one_error_line(err) == "homebench: error: /data/manifests/x.yaml: Input/output error"


# ------------------------------------------------------------------ images a run will read


def _truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:200])


def _wrong_size(path: Path) -> None:
    from homebench.fileio import read_grey, write_png

    write_png(path, read_grey(path)[:, :-1])


@pytest.mark.parametrize(
    "damage",
    [_truncate, lambda p: p.write_bytes(b""), lambda p: p.write_text("not an image"), _wrong_size],
    ids=["truncated", "empty", "text", "wrong-size"],
)
def test_a_corrupt_image_stops_the_run_before_any_job(
    tmp_path: Path, database: Path, damage: Callable[[Path], None]
) -> None:
    victim = database.parent / "pano" / "p2-3.png"
    damage(victim)
    result = _run(tmp_path, database)
    assert result.exit_code == 2
    assert str(victim) in _one_error_line(result.stderr)
    assert _no_jobs_ran(tmp_path / "run")


def test_damage_only_decoding_finds_still_names_the_file(tmp_path: Path, database: Path) -> None:
    """A PNG with an intact header and end but scrambled pixel data fails in the jobs that
    decode it, and each of those failures names the file."""
    victim = database.parent / "pano" / "p1-2.png"  # a goal of the arena config
    data = bytearray(victim.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 64] = bytes(64)
    victim.write_bytes(bytes(data))
    result = _run(tmp_path, database)
    assert result.exit_code == 1
    decoding = [line for line in result.stderr.splitlines() if "cannot be decoded" in line]
    assert decoding and all(str(victim) in line for line in decoding)


# ------------------------------------------------------------------ image kinds


def test_a_raw_image_method_on_an_unfolded_only_database(tmp_path: Path, database: Path) -> None:
    methods = [{"method": "warping"}, {"method": "sift", "label": "sift-P"}]
    result = _run(tmp_path, database, methods=methods)
    assert result.exit_code == 2
    line = _one_error_line(result.stderr)
    assert "'sift-P'" in line and "'arena'" in line and "raw" in line
    assert _no_jobs_ran(tmp_path / "run")


@pytest.mark.parametrize("existing", [False, True])
def test_a_run_refused_before_its_jobs_leaves_no_run_folder(
    tmp_path: Path, database: Path, existing: bool
) -> None:
    """A run refused while it prepares its databases made the run folder (to lock it) and
    left it behind with only the lock in it; a folder the user made stays, emptied of locks."""
    run_dir = tmp_path / "run"
    if existing:
        run_dir.mkdir()
    (database.parent / "pano" / "p2-3.png").write_bytes(b"")
    result = _run(tmp_path, database)
    assert result.exit_code == 2
    assert run_dir.exists() == existing
    assert not existing or not any(run_dir.iterdir())
