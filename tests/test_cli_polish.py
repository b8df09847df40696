"""The command line's rough edges: "did you mean", progress bars on world generation, a listing
cut short by ``head``, the contact sheet's convention marks, the config docstring's example."""

from __future__ import annotations

import io
import math
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from test_generate import FakeRenderer, small_spec

import homebench.config
from homebench.cli import main
from homebench.config import load_config
from homebench.data import generate as generate_module
from homebench.data import progress as progress_module
from homebench.data.progress import progress_bars
from homebench.errors import DataError
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry
from homebench.report.contact_sheet import mark_panorama, mark_raw


def _invoke(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


def _config(tmp_path: Path, **changes: object) -> Path:
    config = {
        "name": "typo",
        "output": str(tmp_path / "run"),
        "databases": {"room": {"world": {"grid": {"shape": [2, 2]}}}},
        "conditions": ["room-room"],
        "goals": [[0, 0]],
        "methods": [{"method": "warping"}],
        **changes,
    }
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


# --------------------------------------------------------------------------- did you mean


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"methods": [{"method": "sfit"}]},
            "methods.0: unknown method 'sfit' (did you mean 'sift'?)",
        ),
        (
            {"methods": [{"method": "sift", "params": {"ratoi": 0.8}}]},
            "methods.0: method 'sift' has no parameter(s) ratoi (did you mean 'ratio'?)",
        ),
        ({"methodz": []}, "unknown key 'methodz' (did you mean 'methods'?)"),
        (
            {"metrics": {"ahc": {"bin_strat_cm": 30}}},
            "metrics.ahc: unknown key 'bin_strat_cm' (did you mean 'bin_start_cm'?)",
        ),
        ({"conditions": ["room-rooom"]}, "unknown database alias 'rooom' (did you mean 'room'?)"),
        (
            {"databases": {"room": "synth-orignal"}},
            "unknown database 'synth-orignal' (did you mean 'synth-original'?)",
        ),
    ],
)
def test_a_misspelt_name_in_a_config_names_the_closest_one(
    tmp_path: Path, changes: dict[str, object], message: str
) -> None:
    code, _, err = _invoke("run", str(_config(tmp_path, **changes)), "--no-progress")
    assert code == 2, err
    assert message in err and err.count("\n") == 1


def test_a_name_close_to_nothing_lists_the_known_ones(tmp_path: Path) -> None:
    code, _, err = _invoke("run", str(_config(tmp_path, methods=[{"method": "qqqq"}])))
    assert code == 2
    assert "unknown method 'qqqq'; known: " in err and ", sift, " in err
    assert "did you mean" not in err


@pytest.mark.parametrize("command", ["generate", "verify", "show"])
def test_data_commands_suggest_the_closest_database(command: str, tmp_path: Path) -> None:
    code, out, err = _invoke("data", command, "synth-dya")
    assert code == 2 and out == ""
    assert err == "homebench: error: unknown database 'synth-dya' (did you mean 'synth-day'?)\n"


def test_data_generate_suggests_the_closest_variant() -> None:
    code, _, err = _invoke("data", "generate", "synth-original", "--variant", "arboral")
    assert code == 2
    assert err == "homebench: error: unknown variant 'arboral' (did you mean 'arboreal'?)\n"


# --------------------------------------------------------------------------- progress


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _generate_with_stderr(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, stream: io.StringIO, bars: bool
) -> str:
    monkeypatch.setattr(sys, "stderr", stream)
    with progress_bars(bars):
        generate_module.generate(small_spec(), tmp_path / "set", renderer=FakeRenderer())
    return stream.getvalue()


def test_generation_shows_a_bar_over_positions_on_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shown = _generate_with_stderr(tmp_path, monkeypatch, _Terminal(), bars=True)
    assert "generate synth" in shown and "12/12" in shown and "position" in shown


def test_no_generation_progress_when_hidden(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert _generate_with_stderr(tmp_path / "a", monkeypatch, _Terminal(), bars=False) == ""
    assert _generate_with_stderr(tmp_path / "b", monkeypatch, io.StringIO(), bars=False) == ""


#: A progress line of a log: what, percent, done of total, seconds so far.
LOG_LINE = re.compile(r"generate (\S+): (\d+) % \((\d+) of (\d+) positions, \d+ s\)")


def _log_percents(text: str, total: int) -> list[int]:
    """The percents of ``text``'s lines, each a progress line of ``total`` positions."""
    found = [LOG_LINE.fullmatch(line) for line in text.splitlines()]
    assert all(found) and found, text
    assert {int(m[4]) for m in found if m} == {total}
    return [int(m[2]) for m in found if m]


def test_generation_in_a_log_says_a_line_per_tenth(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Not a terminal (a log file, a pipe): no bar redrawn, a line per 10 % instead (12
    positions one by one: 8 % a step, one line at the first step into each tenth)."""
    percents = _log_percents(_generate_with_stderr(tmp_path, monkeypatch, io.StringIO(), True), 12)
    assert percents == sorted(set(percents)) and percents[-1] == 100
    assert len(percents) == 10 and {p // 10 for p in percents} == set(range(1, 11))


def test_verifying_a_large_database_shows_bars_over_its_images(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A million-row Brains on Board route took minutes to read, check and decode, saying
    nothing. (Here ten rows, and the bars shown at once instead of after 2 s.)"""
    from bob_folders import write_route

    from homebench.data.bob import open_bob
    from homebench.data.verify import verify_posed

    folder = write_route(tmp_path / "route")
    monkeypatch.setattr(progress_module, "ITEM_BAR_DELAY_S", 0.0)
    monkeypatch.setattr(sys, "stderr", _Terminal())
    db = open_bob(folder)
    verify_posed(db)
    shown = sys.stderr.getvalue()
    assert "read database_entries.csv: 10row" in shown, shown
    assert f"check {db.name}" in shown and f"decode {db.name}" in shown and "10/10" in shown


@pytest.mark.parametrize(("flags", "shown"), [((), True), (("--no-progress",), False)])
def test_run_passes_no_progress_to_the_generation_it_triggers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, flags: tuple[str, ...], shown: bool
) -> None:
    seen = []

    def fake_run_plan(*args: object, **kwargs: object) -> None:
        seen.append(progress_module._BARS.get())
        raise DataError("stopped before any work")

    monkeypatch.setattr("homebench.api.run_plan", fake_run_plan)
    code, _, err = _invoke("run", str(_config(tmp_path)), *flags)
    assert code == 2 and "stopped before any work" in err
    assert seen == [shown]


def _tiny_manifest(tmp_path: Path) -> Path:
    manifest = tmp_path / "tiny.yaml"
    manifest.write_text(generate_module.manifest_for_spec(small_spec(), "tiny").to_yaml())
    return manifest


#: What `data generate` says it made, and how long it took.
MADE = re.compile(
    r"tiny: generated in (\d+\.\d) s: world posters, variant original, seed 0; grid 3 x 4, "
    r"0\.30 m apart; 24 images \(raw 64 x 48, unfolded 36 x 10\) in (\S+)"
)


def test_data_generate_says_what_it_made_and_has_no_progress(tmp_path: Path) -> None:
    manifest, folder = _tiny_manifest(tmp_path), tmp_path / "set"
    code, out, err = _invoke(
        "data", "generate", str(manifest), "--out", str(folder), "-j", "1", "--no-progress"
    )  # fmt: skip
    assert code == 0, err
    made = MADE.fullmatch(out.strip())
    assert made and made[2] == str(folder) and err == "", out
    code, out, err = _invoke("data", "generate", str(manifest), "--out", str(folder))
    assert code == 0 and err == "", err
    assert out.startswith("tiny: already generated: world posters") and str(folder) in out


def test_data_generate_in_a_log_prints_progress_lines_and_what_it_made(tmp_path: Path) -> None:
    """A real process, stderr a pipe as in a batch job's log (about 3 s)."""
    manifest, folder = _tiny_manifest(tmp_path), tmp_path / "set"
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "data", "generate", str(manifest), "--out",
         str(folder), "-j", "1"],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert _log_percents(done.stderr, 12)[-1] == 100
    made = MADE.fullmatch(done.stdout.strip())
    assert made and made[2] == str(folder), done.stdout


# --------------------------------------------------------------------------- methods | head


def test_methods_piped_into_head_prints_one_line_and_no_error() -> None:
    result = subprocess.run(
        f"'{sys.executable}' -m homebench methods | head -1",
        shell=True,
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    first = _invoke("methods")[1].splitlines()[0]
    assert result.stdout == f"{first}\n" and first.startswith("alv ")
    assert result.stderr == ""


def test_methods_reader_leaving_after_some_bytes_is_no_error() -> None:
    process = subprocess.Popen(
        [sys.executable, "-m", "homebench", "methods"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert process.stdout.read(20) == _invoke("methods")[1].encode()[:20]
    process.stdout.close()
    stderr = process.stderr.read()
    process.stderr.close()
    assert process.wait(timeout=120) == 0 and stderr == b""


def test_methods_shows_type_default_and_meaning() -> None:
    code, out, _ = _invoke("methods", "warping")
    assert code == 0
    lines = out.splitlines()
    k = lines.index("    n_rho = 20 (int)")
    assert lines[k + 1].startswith("        ") and len(lines[k + 1].split()) > 2  # its meaning


# --------------------------------------------------------------------------- contact sheet

SCALE = 4  # figure pixels per image pixel


def _render(shape: tuple[int, int], mark: object) -> tuple[np.ndarray, Figure]:
    """RGB pixels of a black image of ``shape`` with ``mark(ax)`` drawn on it, the image
    filling the figure at SCALE figure pixels per image pixel."""
    height, width = shape
    fig = Figure(figsize=(width * SCALE / 100, height * SCALE / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(np.zeros(shape, np.uint8), cmap="gray", vmin=0, vmax=255)
    mark(ax)  # type: ignore[operator]
    ax.set_axis_off()
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].astype(float), fig


def _image_coordinates(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) image coordinates of the figure pixels in ``mask`` (pixel centres at integers)."""
    rows, columns = np.nonzero(mask)
    return (columns + 0.5) / SCALE - 0.5, (rows + 0.5) / SCALE - 0.5


def _red(rgb: np.ndarray) -> np.ndarray:
    return (
        (rgb[..., 0] > 80) & (rgb[..., 1] < 0.3 * rgb[..., 0]) & (rgb[..., 2] < 0.3 * rgb[..., 0])
    )


def _blue(rgb: np.ndarray) -> np.ndarray:
    return (rgb[..., 2] > 80) & (rgb[..., 0] < 0.4 * rgb[..., 2])


def test_panorama_marks_azimuth_0_and_the_horizon_where_the_geometry_puts_them() -> None:
    # azimuth 0 at column 37, azimuth growing to the left (cw); rows +20 deg to -40 deg in 30
    # rows of 2 deg: the horizon is 10 rows down from the top edge, row 9.5
    geometry = PanoramaGeometry(
        120, 30, math.radians(20), math.radians(-40), direction="cw", zero_column=37.0
    )
    marks: list[object] = []
    rgb, fig = _render((30, 120), lambda ax: marks.extend(mark_panorama(ax, geometry)))
    ax = fig.axes[0]
    assert list(ax.get_xticks()) == [37.0, 7.0, 97.0, 67.0]  # az 0, 90, 180, 270 deg (cw)
    assert [t.get_text() for t in ax.get_xticklabels()] == ["az 0°", "az 90°", "az 180°", "az 270°"]
    assert list(marks[0].get_xdata()) == [37.0, 37.0] and list(marks[1].get_ydata()) == [9.5, 9.5]
    u, v = _image_coordinates(_red(rgb))
    u = u[(v > 3) & (v < 26)]  # the line, not the triangles on the edges
    assert abs(np.median(u) - 37.0) <= 0.25 and np.ptp(u) < 1.5  # one line, where predicted
    _, v = _image_coordinates(_blue(rgb))
    assert abs(np.median(v) - 9.5) <= 0.25 and np.ptp(v) < 1.5


def test_raw_marks_the_azimuth_0_ray_and_the_horizon_circle() -> None:
    # azimuth 0 at image angle 30 deg (ccw from +u), elevation +50 deg at radius 10 falling to
    # -30 deg at radius 60: the horizon circle's radius is 10 + 50 * 50 / 80 = 41.25 px
    geometry = CatadioptricGeometry(
        200, 160, (90.0, 70.0), (10.0, 60.0), (math.radians(50), math.radians(-30)),
        direction="cw", zero_angle=math.radians(30),
    )  # fmt: skip
    marks: list[object] = []
    rgb, _ = _render((160, 200), lambda ax: marks.extend(mark_raw(ax, geometry)))
    ray, quarter, circle = marks
    np.testing.assert_allclose(ray.get_xdata(), [90, 90 + 60 * math.cos(math.radians(30))])
    np.testing.assert_allclose(ray.get_ydata(), [70, 70 - 60 * math.sin(math.radians(30))])
    np.testing.assert_allclose(quarter.get_xdata(), [90, 90 + 60 * math.cos(math.radians(-60))])
    np.testing.assert_allclose(quarter.get_ydata(), [70, 70 + 60 * math.sin(math.radians(60))])
    assert circle.center == (90.0, 70.0) and circle.radius == pytest.approx(41.25)
    u, v = _image_coordinates(_red(rgb))
    far = np.hypot(u - 90, v - 70) > 8
    angles = np.degrees(np.arctan2(-(v[far] - 70), u[far] - 90))
    assert far.sum() > 100 and np.all(np.abs(angles - 30) < 2.5)
    u, v = _image_coordinates(_blue(rgb))
    assert np.all(np.abs(np.hypot(u - 90, v - 70) - 41.25) < 1.0)


def test_data_show_on_an_unfolded_only_set(arena_manifest: Path, tmp_path: Path) -> None:
    code, out, err = _invoke("data", "show", str(arena_manifest), "--out", str(tmp_path))
    assert code == 0, err
    assert Path(out.strip()).is_file()


# --------------------------------------------------------------------------- config docstring


def test_the_config_docstring_example_is_a_valid_config(tmp_path: Path) -> None:
    doc = homebench.config.__doc__
    example = textwrap.dedent(doc.split("::\n", 1)[1].split("\n\n")[0])
    path = tmp_path / "example.yaml"
    path.write_text(example)
    config = load_config(path)
    assert config.name == "quickstart"
    labels = [label for label, _, _ in config.method_points()]
    assert labels == ["warping", "warping-coarse", "alv-vc"]
    assert config.methods[2].compass == "visual"
    assert config.methods[1].params == {"n_rho": 10}
