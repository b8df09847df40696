"""Method parameters are checked against their fields' types before anything runs: a value of
the wrong type is a config error (exit 2) naming the key and the type, in grid, route and
closed-loop configs, in overrides and ``grid:`` sweeps, for built-in and plugin methods alike;
a method lists and takes only the parameters that apply to it."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar

import pytest
import yaml
from click.testing import CliRunner, Result
from conftest import arena_config, run_config
from plugins import install_plugin
from pydantic import AllowInfNan, Field

from homebench.cli import main
from homebench.config import load_config
from homebench.errors import ConfigError
from homebench.experiments.closed_loop.config import load_closed_loop_config
from homebench.experiments.route.config import load_route_config
from homebench.methods import registry
from homebench.methods.param_types import parameter_problem
from homebench.methods.warping.method import Warping

#: (warping parameter, value, what the error says) for values of the wrong type.
BAD = [
    ("n_rho", 2.5, "expected an integer, got 2.5"),
    ("n_rho", math.nan, "expected an integer, got nan"),
    ("rho_max", math.nan, "expected a finite number, got nan"),
    ("rho_max", math.inf, "expected a finite number, got inf"),
    ("rho_max", -math.inf, "expected a finite number, got -inf"),
    ("n_rho", "abc", "expected an integer, got 'abc'"),
    ("n_rho", [10, 20], "expected an integer, got [10, 20]"),
    ("n_rho", True, "expected an integer, got True"),
    ("rho_max", False, "expected a finite number, got False"),
    ("n_rho", None, "expected an integer, got None"),
    ("normalize", 3, "expected one of none, equalize, zscore, got 3"),
]
IDS = [f"{name}={value!r}" for name, value, _ in BAD]


def _write(folder: Path, config: dict[str, Any]) -> Path:
    path = folder / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


def _grid(folder: Path, *methods: dict[str, Any]) -> Path:
    """A grid config over a generated world (never generated: the config is refused first)."""
    return _write(
        folder,
        {
            "output": str(folder / "run"),
            "databases": {"room": {"world": {"grid": {"shape": [2, 2]}}}},
            "conditions": ["room-room"],
            "goals": [[0, 0]],
            "methods": list(methods),
        },
    )


def _route(folder: Path, *methods: dict[str, Any], **changes: Any) -> Path:
    route = {"name": "r", "waypoints": [[0.0, 0.0], [1.0, 0.0]]}
    config = {"kind": "route", "output": str(folder / "run"), "routes": [route]}
    return _write(folder, {**config, "methods": [{"method": "klt-sector"}, *methods], **changes})


def _closed_loop(folder: Path, *methods: dict[str, Any]) -> Path:
    return _write(
        folder,
        {
            "kind": "closed-loop",
            "output": str(folder / "run"),
            "goals": [{"grid": [1, 1]}],
            "starts": {"spacing": 0.5},
            "methods": list(methods),
        },
    )


def _run(path: Path, *overrides: str) -> Result:
    return CliRunner().invoke(main, ["run", str(path), *overrides, "--no-progress"])


def _refused(result: Result, path: Path, key: str, message: str) -> None:
    """Exit 2 with one line naming the file, the key and the type, and no run folder."""
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith(f"homebench: error: {path}"), result.stderr
    assert f"{key}: {message}\n" in result.stderr
    assert result.stderr.count("\n") == 1, result.stderr
    assert not (path.parent / "run").exists()


@pytest.mark.parametrize(("name", "value", "message"), BAD, ids=IDS)
def test_a_grid_config_refuses_a_value_of_the_wrong_type(
    tmp_path: Path, name: str, value: Any, message: str
) -> None:
    path = _grid(tmp_path, {"method": "warping", "params": {name: value}})
    with pytest.raises(ConfigError, match=re.escape(f"methods.0.params.{name}: {message}")):
        load_config(path)
    _refused(_run(path), path, f"methods.0.params.{name}", message)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("n_rho=2.5", "expected an integer, got 2.5"),
        ("n_rho=.nan", "expected an integer, got nan"),
        ("rho_max=.inf", "expected a finite number, got inf"),
        ("n_rho=abc", "expected an integer, got 'abc'"),
        ("n_rho=[1, 2]", "expected an integer, got [1, 2]"),
        ("n_rho=true", "expected an integer, got True"),
    ],
)
def test_an_override_of_the_wrong_type_is_refused(
    tmp_path: Path, override: str, message: str
) -> None:
    path = _grid(tmp_path, {"method": "warping"})
    key = f"methods.0.params.{override.partition('=')[0]}"
    _refused(_run(path, f"methods.0.params.{override}"), path, key, message)


def test_a_sweep_names_the_value_of_the_wrong_type(tmp_path: Path) -> None:
    path = _grid(tmp_path, {"method": "warping", "grid": {"n_rho": [10, 2.5], "rho_max": [0.9]}})
    _refused(_run(path), path, "methods.0.grid.n_rho.1", "expected an integer, got 2.5")
    path = _grid(tmp_path, {"method": "warping", "grid": {"rho_max": [0.5, math.nan]}})
    _refused(_run(path), path, "methods.0.grid.rho_max.1", "expected a finite number, got nan")


@pytest.mark.parametrize(("name", "value", "message"), BAD, ids=IDS)
def test_a_route_config_refuses_a_value_of_the_wrong_type(
    tmp_path: Path, name: str, value: Any, message: str
) -> None:
    path = _route(tmp_path, {"method": "warping", "params": {name: value}})
    with pytest.raises(ConfigError, match=re.escape(f"methods.1.params.{name}: {message}")):
        load_route_config(path)
    _refused(_run(path), path, f"methods.1.params.{name}", message)


def test_a_route_config_checks_the_trackers_parameters(tmp_path: Path) -> None:
    path = _route(tmp_path, tracker={"max_corners": 2.5})
    _refused(_run(path), path, "max_corners", "expected an integer, got 2.5")


@pytest.mark.parametrize(("name", "value", "message"), BAD, ids=IDS)
def test_a_closed_loop_config_refuses_a_value_of_the_wrong_type(
    tmp_path: Path, name: str, value: Any, message: str
) -> None:
    path = _closed_loop(tmp_path, {"method": "warping", "grid": {name: [value]}})
    with pytest.raises(ConfigError, match=re.escape(f"methods.0.grid.{name}.0: {message}")):
        load_closed_loop_config(path)
    _refused(_run(path), path, f"methods.0.grid.{name}.0", message)


def test_values_of_the_right_type_run(tmp_path: Path, arena_manifest: Path) -> None:
    """An integer where a float is expected, a list where a tuple is, null where it may be;
    a whole float is no integer."""
    methods = [
        {"method": "warping", "params": {"n_rho": 8.0}},
        {"method": "mfdid", "params": {"elevation_range_deg": [-20, 20]}},
        {"method": "alv", "grid": {"n_columns": [None, 72]}},
    ]
    path = _write(tmp_path, arena_config(tmp_path, arena_manifest, methods=methods))
    _refused(_run(path), path, "methods.0.params.n_rho", "expected an integer, got 8.0")
    methods[0]["params"] = {"n_rho": 8, "band_half_width_deg": 5}
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, methods=methods))
    assert result.exit_code == 0, result.output
    assert (tmp_path / "run" / "tables").is_dir()


def test_a_method_made_in_python_is_checked_too() -> None:
    with pytest.raises(ConfigError, match="warping: n_rho: expected an integer, got 2.5"):
        Warping(n_rho=2.5)  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="method 'warping': rho_max: expected a finite number"):
        registry.create("warping", rho_max=math.inf)


class _OwnType:
    """A parameter type pydantic cannot check."""


@dataclass(frozen=True)
class _Plugin:
    """A third-party method's parameters: annotated, opting out, unresolvable, free."""

    name: ClassVar[str] = "plugin"
    steps: int = 1
    limit: Annotated[float, AllowInfNan()] = math.inf
    seed: Annotated[int, Field(ge=0)] = 0
    window: tuple[int, int] = (1, 2)
    mode: UndefinedAlias = "fast"  # noqa: F821  (an annotation that does not resolve)
    anything: Any = None
    own: _OwnType | None = None


@pytest.mark.parametrize(
    ("name", "value", "problem"),
    [
        ("steps", 2.5, "expected an integer, got 2.5"),
        ("steps", 2, ""),
        ("limit", math.inf, ""),
        ("limit", math.nan, ""),
        ("limit", "far", "expected a number, got 'far'"),
        ("seed", -1, "expected an integer >= 0, got -1"),
        ("seed", 0, ""),
        ("window", [3, 4], ""),
        ("window", (3, 4), ""),
        ("window", [3], "expected a list of 2 integers, got [3]"),
        ("window", [3, 4.5], "expected a list of 2 integers, got [3, 4.5]"),
        ("mode", 3, ""),
        ("anything", math.nan, ""),
        ("own", 3, ""),
        ("unknown", 3, ""),
    ],
)
def test_what_a_type_hint_lets_through(name: str, value: Any, problem: str) -> None:
    assert parameter_problem(_Plugin, name, value) == problem


PLUGIN = '''
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import AllowInfNan, Field

from homebench.methods.base import HomingEstimate


@dataclass(frozen=True)
class Faulty:
    """Test method with annotated parameters."""

    name: ClassVar[str] = "{name}"
    image_kind: ClassVar[str] = "unfolded"
    steps: int = 3
    gain: float = 1.0
    limit: Annotated[float, AllowInfNan()] = math.inf
    mode: Literal["fast", "slow"] = "fast"
    window: tuple[float, float] = (0.0, 1.0)
    hidden: Unresolved = None  # noqa: F821

    def describe(self, view):
        return float(np.mean(view.image))

    def home(self, current, goal):
        return HomingEstimate(angle=0.1, n_landmarks=self.steps)
'''


@pytest.mark.parametrize(
    ("params", "key", "message"),
    [
        ({"steps": 2.5}, "steps", "expected an integer, got 2.5"),
        ({"steps": True}, "steps", "expected an integer, got True"),
        ({"gain": math.nan}, "gain", "expected a finite number, got nan"),
        ({"gain": "x"}, "gain", "expected a finite number, got 'x'"),
        ({"mode": "medium"}, "mode", "expected one of fast, slow, got 'medium'"),
        ({"window": 1.0}, "window", "expected a list of 2 finite numbers, got 1.0"),
    ],
)
def test_a_plugins_annotated_parameters_are_checked(
    tmp_path: Path,
    arena_manifest: Path,
    monkeypatch: pytest.MonkeyPatch,
    params: dict[str, Any],
    key: str,
    message: str,
) -> None:
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, source=PLUGIN)
    entry = {"method": plugin.method, "params": params}
    path = _write(tmp_path, arena_config(tmp_path, arena_manifest, methods=[entry]))
    _refused(_run(path), path, f"methods.0.params.{key}", message)


def test_a_plugin_with_valid_parameters_runs_and_is_listed(
    tmp_path: Path, arena_manifest: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Its opt-out takes inf, its unresolvable annotation anything; the listing shows the
    types that resolve beside the text of the one that does not."""
    plugin = install_plugin(tmp_path / "plugin", monkeypatch, source=PLUGIN)
    params = {"steps": 2, "gain": 2, "limit": math.inf, "window": [0, 2], "hidden": [1]}
    entry = {"method": plugin.method, "params": params}
    result = run_config(tmp_path, arena_config(tmp_path, arena_manifest, methods=[entry]))
    assert result.exit_code == 0, result.output
    listing = CliRunner().invoke(main, ["methods", plugin.method])
    assert listing.exit_code == 0, listing.output
    assert "    limit = inf (float)" in listing.stdout
    assert "    mode = 'fast' (one of fast | slow)" in listing.stdout
    assert "    window = (0.0, 1.0) (tuple[float, float])" in listing.stdout
    assert "    hidden = None (Unresolved)" in listing.stdout


def test_infomax_refuses_a_negative_seed(tmp_path: Path) -> None:
    """It passed the config check, then every trial failed without naming the key."""
    path = _route(tmp_path, {"method": "infomax", "params": {"seed": -1}})
    _refused(_run(path), path, "methods.1.params.seed", "expected an integer >= 0, got -1")
    listing = CliRunner().invoke(main, ["methods", "infomax"])
    assert "    seed = 0 (int >= 0)" in listing.stdout


def _listed(name: str) -> list[str]:
    """The parameter names ``homebench methods`` lists for method ``name``."""
    result = CliRunner().invoke(main, ["methods", name])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    end = lines.index("")  # the entry-level keys follow
    return [line.split()[0] for line in lines[2:end] if line[4] != " "]  # after header, paper


def test_sift_unfolded_has_no_annulus_to_mask(tmp_path: Path) -> None:
    assert "mask_annulus" in _listed("sift")
    assert "mask_annulus" not in _listed("sift-unfolded")
    assert set(_listed("sift")) - set(_listed("sift-unfolded")) == {"mask_annulus"}
    path = _grid(tmp_path, {"method": "sift-unfolded", "params": {"mask_annulus": False}})
    result = _run(path)
    assert result.exit_code == 2, result.output
    assert "methods.0: method 'sift-unfolded' has no parameter(s) mask_annulus" in result.stderr
    assert not (tmp_path / "run").exists()
