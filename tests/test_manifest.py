"""homebench.data.manifest: the schema, its strict validation and its error messages."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from homebench.data.catalog import SHIPPED_MANIFESTS
from homebench.data.generate import manifest_for_spec
from homebench.data.manifest import Manifest, load_manifest, parse_manifest
from homebench.data.synth.spec import GridSpec, WorldSpec
from homebench.errors import ConfigError, DataError
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry

VALID = """\
schema: 1
name: my-lab
description: a test database
grid: {shape: [4, 3], spacing: 0.5, origin: [1.0, 2.0]}
heading_deg: 90.0
headings_deg: {"2_1": 180.0}
images:
  raw:
    pattern: "r{x:02d}-{y:02d}.{ext}"
    extensions: [pgm, png]
    size: [64, 48]
    catadioptric:
      centre: [31.5, 23.5]
      radii: [4, 20]
      elevations_deg: [-40, 30]
      direction: cw
      zero_angle_deg: 90
    files: {"r00-00.pgm": null}
  unfolded:
    folder: pano
    pattern: "{x}_{y}.png"
    size: [72, 20]
    panorama: {elevation_top_deg: 30, elevation_bottom_deg: -40}
"""


def _load(tmp_path: Path, text: str) -> Manifest:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    return load_manifest(path)


def test_valid_manifest_converts_degrees_to_geometry(tmp_path: Path) -> None:
    m = _load(tmp_path, VALID)
    assert m.name == "my-lab" and m.kind == "real" and m.kinds == ("raw", "unfolded")
    raw = m.geometry("raw")
    assert isinstance(raw, CatadioptricGeometry)
    assert (raw.width, raw.height, raw.direction) == (64, 48, "cw")
    assert raw.elevations == pytest.approx((math.radians(-40), math.radians(30)))
    assert raw.zero_angle == pytest.approx(math.pi / 2)
    pano = m.geometry("unfolded")
    assert isinstance(pano, PanoramaGeometry)
    assert (pano.width, pano.height, pano.direction, pano.zero_column) == (72, 20, "ccw", 0.0)
    assert pano.elevation_top == pytest.approx(math.radians(30))
    grid = m.to_grid()
    assert grid.shape == (4, 3) and grid.spacing == 0.5 and grid.origin == (1.0, 2.0)
    assert m.heading(0, 0) == pytest.approx(math.pi / 2)
    assert m.heading(2, 1) == pytest.approx(math.pi)


def test_file_names_follow_the_pattern_and_parse_back(tmp_path: Path) -> None:
    raw = _load(tmp_path, VALID).section("raw")
    assert raw.file_names(3, 12) == ["r03-12.pgm", "r03-12.png"]
    assert raw.parse_name("r03-12.png") == (3, 12)
    assert raw.parse_name("r3-12.png") is None  # not what the pattern writes
    assert raw.parse_name("r03-12.jpg") is None  # not a listed extension
    unfolded = _load(tmp_path, VALID).section("unfolded")
    assert unfolded.parse_path("pano/2_1.png") == (2, 1)
    assert unfolded.parse_path("2_1.png") is None
    assert unfolded.relative_path("2_1.png") == "pano/2_1.png"


def test_to_yaml_round_trips(tmp_path: Path) -> None:
    m = _load(tmp_path, VALID)
    assert parse_manifest(m.to_yaml(), "again") == m


def test_a_missing_kind_is_a_data_error(tmp_path: Path) -> None:
    text = VALID[: VALID.index("  unfolded:")]
    m = _load(tmp_path, text)
    assert m.kinds == ("raw",)
    with pytest.raises(DataError, match="no 'unfolded' images"):
        m.geometry("unfolded")


@pytest.mark.parametrize("path", sorted(SHIPPED_MANIFESTS.glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_manifests_load(path: Path) -> None:
    m = load_manifest(path)
    assert m.name == path.stem
    assert m.kind == ("generated" if m.name.startswith("synth-") else "real")
    if m.kind == "real":
        assert m.grid.shape == (10, 17) and m.grid.spacing == 0.30
        assert m.section("raw").size == (752, 564)
        assert m.source is not None and m.source.path_env


def test_shipped_manifests_cover_the_sets() -> None:
    names = {p.stem for p in SHIPPED_MANIFESTS.glob("*.yaml")}
    bielefeld = {f"bielefeld-{v}" for v in ("original", "arboreal", "chairs", "day")}
    variants = ("original", "arboreal", "chairs", "day", "twilight", "winlit")
    synth = {f"synth-{v}" for v in variants}  # the poster room
    styles = {f"synth-{s}-{v}" for s in ("lab", "corridor", "outdoor") for v in variants}
    assert names == bielefeld | synth | styles


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        # unknown keys, at any depth: file, line and key path
        ("heading_deg: 90.0", "heading_deg: 90.0\ncolour: red", r"m\.yaml:6: colour: Extra"),
        # a near miss names the key meant (the strict base of every config and manifest)
        ("heading_deg: 90.0", "heading_deg: 90.0\nheadings_degs: {}", r"mean 'headings_deg'"),
        (
            "      direction: cw",
            "      direction: cw\n      focal: 3",
            r":17: images\.raw\.catadioptric\.focal:",
        ),
        # wrong types
        ("spacing: 0.5", "spacing: half", r"m\.yaml:4: grid\.spacing: Input should be a valid"),
        ("size: [64, 48]", "size: [64, 48.5]", r":11: images\.raw\.size\[1\]: .*integer"),
        ("size: [64, 48]", 'size: ["64", 48]', r"images\.raw\.size\[0\]: .*integer"),
        ("schema: 1", "schema: 2", r"m\.yaml:1: schema: Input should be 1"),
        ("direction: cw", "direction: clockwise", r"images\.raw\.catadioptric\.direction"),
        # bad values
        ("shape: [4, 3]", "shape: [0, 3]", r"grid\.shape: .*at least"),
        ("spacing: 0.5", "spacing: -1", r"grid\.spacing: .*greater than 0"),
        ('"r{x:02d}-{y:02d}.{ext}"', '"r{x}.{ext}"', r"images\.raw\.pattern: .*\{y\}"),
        ('"r{x:02d}-{y:02d}.{ext}"', '"r{x}_{y}_{z}.png"', r"images\.raw\.pattern"),
        ("folder: pano", "folder: ../elsewhere", r"images\.unfolded\.folder: .*inside"),
        ('"2_1": 180.0', '"9_9": 180.0', r"headings_deg: '9_9' is outside"),
        ('"2_1": 180.0', '"north": 180.0', r"headings_deg: 'north' is not a grid key"),
        ('"r00-00.pgm": null', '"r00-00.pgm": abc', r"images\.raw\.files\.r00-00\.pgm"),
        ('"r00-00.pgm": null', '"r99-00.pgm": null', r"'r99-00\.pgm' is outside the grid"),
        ('"r00-00.pgm": null', '"x.pgm": null', r"does not match the pattern"),
        ("elevations_deg: [-40, 30]", "elevations_deg: [10, 30]", r"span the horizon"),
        ("name: my-lab", "name: my lab", r"name: String should match"),
        ("description: a test database", "ground_truth: gt.json", r"only for generated sets"),
        ("extensions: [pgm, png]", "extensions: [.pgm]", r"without a dot"),
    ],
)
def test_invalid_manifests_name_file_line_and_key_path(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    assert old in VALID
    with pytest.raises(ConfigError, match=expected) as info:
        _load(tmp_path, VALID.replace(old, new, 1))
    assert str(tmp_path / "m.yaml") in str(info.value)


def test_yaml_syntax_error_gives_line_and_column(tmp_path: Path) -> None:
    text = VALID.replace("size: [64, 48]", "size: [64, 48", 1)
    with pytest.raises(ConfigError, match=r"m\.yaml:\d+:\d+: YAML syntax error"):
        _load(tmp_path, text)
    with pytest.raises(ConfigError, match=r"m\.yaml:3:6: YAML syntax error"):
        _load(tmp_path, "schema: 1\nname: x\n  bad: indent\n")


def test_duplicate_keys_are_errors(tmp_path: Path) -> None:
    text = VALID.replace("heading_deg: 90.0", "heading_deg: 90.0\nheading_deg: 0.0", 1)
    with pytest.raises(ConfigError, match=r"m\.yaml:6:1: duplicate key 'heading_deg'"):
        _load(tmp_path, text)


@pytest.mark.parametrize(("text", "expected"), [("", "empty"), ("- 1\n- 2\n", "mapping")])
def test_empty_or_non_mapping_manifest(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(ConfigError, match=expected):
        _load(tmp_path, text)


def test_unreadable_manifest_names_the_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="nothere.yaml"):
        load_manifest(tmp_path / "nothere.yaml")


def _small_spec(**fields: object) -> WorldSpec:
    return WorldSpec(grid=GridSpec(shape=(3, 2)), **fields)


def test_generated_manifest_round_trips_the_exact_spec() -> None:
    spec = _small_spec(seed=7, variant="day", heading_deg=30.0)
    m = manifest_for_spec(spec, "tiny")
    again = parse_manifest(m.to_yaml(), "tiny.yaml")
    assert again.generator.spec == spec
    assert again.generator.key == spec.key()
    assert again.kind == "generated"
    assert again.to_grid().shape == (3, 2)
    assert again.heading(0, 0) == pytest.approx(math.radians(30.0))
    assert again.geometry("raw") == spec.raw.geometry()


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("  spacing: 0.3\n", "  spacing: 0.4\n", "grid does not match generator.spec"),
        ("heading_deg: 0.0\n", "heading_deg: 10.0\n", "heading_deg must be"),
        ("size: [360, 95]", "size: [360, 96]", r"images.unfolded does not match"),
        ("zero_angle_deg: 90.0\n", "zero_angle_deg: 80.0\n", r"images.raw does not match"),
        ("    variant: original", "    variant: sunny", r"generator\.spec\.variant"),
    ],
)
def test_generated_manifest_must_agree_with_its_spec(old: str, new: str, expected: str) -> None:
    text = manifest_for_spec(_small_spec(), "tiny").to_yaml()
    assert old in text
    with pytest.raises(ConfigError, match=expected):
        parse_manifest(text.replace(old, new, 1), "tiny.yaml")
