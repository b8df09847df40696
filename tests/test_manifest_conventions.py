"""No silent defaults for a manifest's conventions, and one name for a database everywhere.

A missing heading, a zero column off the image, an angle that is no angle: errors naming the
manifest file, line and key. A pattern that names no file: a warning naming the files it
looked for, before the error on the missing images. The data commands name a database alike.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from test_manifest import VALID

from homebench.cli import main
from homebench.data.manifest import load_manifest
from homebench.errors import ConfigError


def _load(tmp_path: Path, text: str) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    load_manifest(path)


def test_the_heading_is_required_and_finite(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"m\.yaml:1: heading_deg is required: .*Bielefeld"):
        _load(tmp_path, VALID.replace("heading_deg: 90.0\n", ""))
    with pytest.raises(ConfigError, match=r"m\.yaml:5: heading_deg: .*finite"):
        _load(tmp_path, VALID.replace("heading_deg: 90.0", "heading_deg: .nan"))


@pytest.mark.parametrize(
    ("old", "edge", "beyond", "expected"),
    [
        (
            "elevation_bottom_deg: -40}",
            "elevation_bottom_deg: -40, zero_column: 71.9}",
            "elevation_bottom_deg: -40, zero_column: 72}",
            r"m\.yaml:19: images\.unfolded: panorama\.zero_column 72 is not a column of the "
            r"72-wide image: it must lie in \[0, 72\)",
        ),
        (
            "elevation_bottom_deg: -40}",
            "elevation_bottom_deg: -40, zero_column: 0}",
            "elevation_bottom_deg: -40, zero_column: -0.5}",
            r"images\.unfolded: panorama\.zero_column -0\.5 is not a column",
        ),
        (
            "zero_angle_deg: 90",
            "zero_angle_deg: -360",
            "zero_angle_deg: 450",
            r"m\.yaml:17: images\.raw\.catadioptric\.zero_angle_deg: 450\.0 is no image angle",
        ),
        (
            "elevations_deg: [-40, 30]",
            "elevations_deg: [-90, 30]",
            "elevations_deg: [-40, 95]",
            r"images\.raw\.catadioptric\.elevations_deg: 95\.0 is no elevation",
        ),
        (
            "elevation_top_deg: 30,",
            "elevation_top_deg: 90,",
            "elevation_top_deg: 120,",
            r"images\.unfolded\.panorama\.elevation_top_deg: 120\.0 is no elevation",
        ),
        (
            "centre: [31.5, 23.5]",
            "centre: [0, 47]",
            "centre: [31.5, 48]",
            r"m\.yaml:8: images\.raw: catadioptric\.centre \[31\.5, 48\] lies outside the "
            r"64 x 48 image",
        ),
    ],
)
def test_conventions_within_their_range_up_to_its_edge(
    tmp_path: Path, old: str, edge: str, beyond: str, expected: str
) -> None:
    assert old in VALID
    _load(tmp_path, VALID.replace(old, edge, 1))
    with pytest.raises(ConfigError, match=expected) as info:
        _load(tmp_path, VALID.replace(old, beyond, 1))
    assert str(tmp_path / "m.yaml") in str(info.value)


def test_a_pattern_that_names_no_file_is_a_warning_naming_what_it_looked_for(
    tmp_path: Path,
) -> None:
    (tmp_path / "pano").mkdir()
    (tmp_path / "pano" / "0_0.png").write_bytes(b"")  # beside the names the raw pattern makes
    manifest = tmp_path / "lab.yaml"
    manifest.write_text(VALID)
    result = CliRunner().invoke(main, ["data", "verify", str(manifest)])
    assert result.exit_code == 2
    warning, error = result.stderr.splitlines()
    assert warning == (
        f"homebench: warning: my-lab ({manifest}): images.raw.pattern "
        f"'r{{x:02d}}-{{y:02d}}.{{ext}}' matches no file: looked for r00-00.pgm|png in {tmp_path}"
    )
    assert error.startswith(f"homebench: error: {tmp_path}: no image for grid position(s)")


def test_a_run_notes_a_pattern_that_names_no_file_of_a_kind_it_does_not_read(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """A raw section typed wrong stays unseen by a run of unfolded-image methods: say so."""
    import shutil

    import yaml
    from conftest import arena_config, run_config

    folder = tmp_path / "arena"
    shutil.copytree(arena_manifest.parent, folder)
    manifest = yaml.safe_load((folder / "manifest.yaml").read_text())
    manifest["images"]["raw"] = {
        "folder": "pano",
        "pattern": "raw_{x}_{y}.png",
        "size": [64, 48],
        "catadioptric": {"centre": [31.5, 23.5], "radii": [3, 22], "elevations_deg": [-50, 45]},
    }
    (folder / "manifest.yaml").write_text(yaml.safe_dump(manifest))
    config = arena_config(tmp_path, folder / "manifest.yaml", methods=[{"method": "warping"}])
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "homebench: note: database 'arena', arena (" in result.stderr
    assert "images.raw.pattern 'raw_{x}_{y}.png' matches no file: looked for raw_0_0.png" in (
        result.stderr
    )
