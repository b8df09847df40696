"""homebench.data.database and homebench.data.catalog: loading grid databases and finding them."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from homebench.data import catalog
from homebench.data.catalog import (
    find_manifest,
    known_manifest,
    known_manifests,
    list_databases,
    resolve,
)
from homebench.data.database import GridDatabase
from homebench.data.manifest import load_manifest
from homebench.errors import (
    CorruptImageError,
    DataError,
    ImageSizeError,
    MissingImagesError,
    UnknownDatabaseError,
)
from homebench.fileio import write_png
from homebench.geometry import PanoramaGeometry

#: A user's own database: 3 x 2 grid, 0.25 m apart, zero-padded names, unfolded images only.
USER_MANIFEST = """\
schema: 1
name: my-corridor
description: a tiny user-made database
grid: {shape: [3, 2], spacing: 0.25, origin: [0.5, 1.0]}
heading_deg: 45.0
headings_deg: {"1_1": -90.0}
images:
  unfolded:
    folder: pano
    pattern: "img-{x:03d}-{y:03d}.png"
    size: [40, 12]
    panorama: {elevation_top_deg: 30, elevation_bottom_deg: -30, direction: cw, zero_column: 5}
"""


def user_image(i: int, j: int) -> np.ndarray:
    """The distinct image a user database holds at (i, j), shape (12, 40)."""
    return np.random.default_rng([i, j]).integers(0, 256, (12, 40), dtype=np.uint8)


def make_user_database(root: Path) -> Path:
    """Write the user database (manifest.yaml and every image) into ``root``; return root."""
    (root / "pano").mkdir(parents=True)
    (root / "manifest.yaml").write_text(USER_MANIFEST)
    for i in range(3):
        for j in range(2):
            write_png(root / "pano" / f"img-{i:03d}-{j:03d}.png", user_image(i, j))
    return root


@pytest.fixture
def user_db(tmp_path: Path) -> GridDatabase:
    root = make_user_database(tmp_path / "corridor")
    return GridDatabase(load_manifest(root / "manifest.yaml"), root)


def test_user_database_loads_images_poses_and_geometry(user_db: GridDatabase) -> None:
    assert user_db.name == "my-corridor" and user_db.kinds == ("unfolded",)
    assert user_db.grid.shape == (3, 2)
    user_db.check_layout()
    np.testing.assert_array_equal(user_db.image(2, 1, "unfolded"), user_image(2, 1))
    view = user_db.view(0, 1, "unfolded")
    assert view.kind == "unfolded"
    np.testing.assert_array_equal(view.image, user_image(0, 1))
    assert view.geometry == PanoramaGeometry(
        40, 12, math.radians(30), math.radians(-30), direction="cw", zero_column=5.0
    )
    pose = user_db.pose(2, 1)
    assert (pose.x, pose.y) == pytest.approx((1.0, 1.25))
    assert pose.heading == pytest.approx(math.pi / 4)
    assert user_db.heading(1, 1) == pytest.approx(-math.pi / 2)
    assert user_db.path(1, 0, "unfolded") == user_db.root / "pano" / "img-001-000.png"


@pytest.mark.parametrize("position", [(3, 0), (0, 2), (-1, 0)])
def test_a_position_outside_the_grid_is_a_clear_error(
    user_db: GridDatabase, position: tuple[int, int]
) -> None:
    with pytest.raises(DataError, match=r"outside database 'my-corridor'.* 3 x 2"):
        user_db.image(*position, "unfolded")
    with pytest.raises(DataError, match="outside"):
        user_db.pose(*position)


def test_a_kind_the_database_lacks_is_a_clear_error(user_db: GridDatabase) -> None:
    with pytest.raises(DataError, match="no 'raw' images"):
        user_db.view(0, 0, "raw")


def test_missing_images_are_named_by_position(user_db: GridDatabase) -> None:
    (user_db.root / "pano" / "img-001-000.png").unlink()
    (user_db.root / "pano" / "img-002-001.png").unlink()
    with pytest.raises(MissingImagesError, match=r"\(1,0\), \(2,1\)") as info:
        user_db.check_layout()
    assert info.value.positions == [(1, 0), (2, 1)]
    with pytest.raises(MissingImagesError, match=r"\(1,0\)"):
        user_db.image(1, 0, "unfolded")
    user_db.image(0, 0, "unfolded")  # the others still load


def test_an_image_of_the_wrong_size_names_the_file(user_db: GridDatabase) -> None:
    path = user_db.root / "pano" / "img-001-001.png"
    write_png(path, np.zeros((12, 41), np.uint8))
    with pytest.raises(ImageSizeError, match=r"img-001-001\.png: image is 41x12.*expected 40x12"):
        user_db.image(1, 1, "unfolded")


@pytest.mark.parametrize("content", [b"", b"\x89PNG\r\n\x1a\n\x00\x00"])
def test_an_unreadable_image_names_the_file(user_db: GridDatabase, content: bytes) -> None:
    (user_db.root / "pano" / "img-000-001.png").write_bytes(content)
    with pytest.raises(CorruptImageError, match=r"img-000-001\.png"):
        user_db.image(0, 1, "unfolded")


def test_extensions_are_tried_in_order(tmp_path: Path) -> None:
    manifest = tmp_path / "manifest.yaml"
    manifest.write_text(
        USER_MANIFEST.replace('"img-{x:03d}-{y:03d}.png"', '"{x}_{y}.{ext}"').replace(
            "    size:", "    extensions: [png, pgm]\n    size:"
        )
    )
    db = GridDatabase(load_manifest(manifest), tmp_path)
    (tmp_path / "pano").mkdir()
    image = user_image(0, 0)
    cv2.imwrite(str(tmp_path / "pano" / "0_0.pgm"), image)
    assert db.path(0, 0, "unfolded").name == "0_0.pgm"
    np.testing.assert_array_equal(db.image(0, 0, "unfolded"), image)
    assert db.path(1, 0, "unfolded").name == "1_0.png"  # absent: the first candidate
    assert db.missing("unfolded") == [(0, 1), (1, 0), (1, 1), (2, 0), (2, 1)]


def test_ground_truth_of_a_real_set_is_a_data_error(user_db: GridDatabase) -> None:
    with pytest.raises(DataError, match="no ground truth"):
        user_db.ground_truth()


# ---------------------------------------------------------------------- catalog


@pytest.fixture
def clean_env(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """No user manifests, an empty data dir and no Bielefeld copies."""
    monkeypatch.delenv("HOMEBENCH_MANIFESTS", raising=False)
    monkeypatch.setenv("HOMEBENCH_DATA", str(tmp_path / "data"))
    for v in ("ORIGINAL", "ARBOREAL", "CHAIRS", "DAY"):
        monkeypatch.delenv(f"HOMEBENCH_BIELEFELD_{v}", raising=False)
    return tmp_path


def test_unknown_name_lists_the_known_ones(clean_env: Path) -> None:
    with pytest.raises(UnknownDatabaseError, match=r"'bielefeld-orignal'.*bielefeld-original"):
        resolve("bielefeld-orignal")


def test_real_set_without_a_copy_says_how_to_point_at_one(clean_env: Path) -> None:
    with pytest.raises(DataError, match="HOMEBENCH_BIELEFELD_ORIGINAL=.*--path"):
        resolve("bielefeld-original")


def test_real_set_from_env_var_or_path(clean_env: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    copy = clean_env / "copy"
    copy.mkdir()
    monkeypatch.setenv("HOMEBENCH_BIELEFELD_DAY", str(copy))
    db = resolve("bielefeld-day")
    assert db.root == copy and db.grid.shape == (10, 17)
    assert db.path(3, 4, "raw") == copy / "3_4.png"
    assert resolve("bielefeld-day", path=clean_env).root == clean_env
    with pytest.raises(DataError, match="does not exist"):
        resolve("bielefeld-day", path=clean_env / "nowhere")


def test_user_database_by_folder_or_manifest_path(clean_env: Path) -> None:
    root = make_user_database(clean_env / "corridor")
    for name in (root, root / "manifest.yaml", str(root / "manifest.yaml")):
        db = resolve(name)
        assert db.root == root and db.name == "my-corridor"
    with pytest.raises(DataError, match="needs a manifest.yaml"):
        find_manifest(clean_env)


def test_user_manifest_folders_join_the_catalog(
    clean_env: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = make_user_database(clean_env / "corridor")
    folder = clean_env / "mine"
    folder.mkdir()
    (folder / "corridor.yaml").write_text(USER_MANIFEST)
    monkeypatch.setenv("HOMEBENCH_MANIFESTS", str(folder))
    assert known_manifests()["my-corridor"].path == folder / "corridor.yaml"
    with pytest.raises(DataError, match="--path"):
        resolve("my-corridor")
    assert resolve("my-corridor", path=root).image(0, 0, "unfolded").shape == (12, 40)


def test_a_name_is_found_as_the_whole_catalog_finds_it_parsing_one_file(
    clean_env: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """known_manifest(name) is known_manifests()[name] (a user folder first, even for a shipped
    name), and parses only files that may declare the name: one for a homebench-written
    manifest, also any whose name line it cannot read cheaply (a quoted name)."""
    folder = clean_env / "mine"
    folder.mkdir()
    (folder / "a-quoted.yaml").write_text(USER_MANIFEST.replace("name: my-corridor",
                                                                'name: "my-quoted"'))  # fmt: skip
    (folder / "corridor.yaml").write_text(USER_MANIFEST)
    (folder / "z-shadow.yaml").write_text(USER_MANIFEST.replace("my-corridor", "synth-day"))
    monkeypatch.setenv("HOMEBENCH_MANIFESTS", str(folder))
    everything = known_manifests()
    parsed: list[str] = []
    original = catalog.load_manifest
    monkeypatch.setattr(catalog, "load_manifest", lambda p: parsed.append(p.name) or original(p))
    for name in ("synth-original", "synth-day", "my-corridor", "my-quoted", "bielefeld-day"):
        parsed.clear()
        entry = known_manifest(name)
        assert entry == everything[name]
        assert parsed == sorted({"a-quoted.yaml", everything[name].path.name}), name
    assert known_manifest("synth-day").path == folder / "z-shadow.yaml"
    assert known_manifest("nothing-of-that-name") is None


def test_list_databases_rows(clean_env: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    root = make_user_database(clean_env / "corridor")
    folder = clean_env / "mine"
    folder.mkdir()
    (folder / "corridor.yaml").write_text(USER_MANIFEST)
    monkeypatch.setenv("HOMEBENCH_MANIFESTS", str(folder))
    monkeypatch.setenv("HOMEBENCH_BIELEFELD_CHAIRS", str(root))
    rows = {r.name: r for r in list_databases()}
    assert {"bielefeld-original", "synth-day", "my-corridor"} <= set(rows)
    assert rows["bielefeld-original"].kind == "real"
    assert rows["bielefeld-original"].location == "$HOMEBENCH_BIELEFELD_ORIGINAL not set"
    assert not rows["bielefeld-original"].present
    assert rows["bielefeld-chairs"].location == str(root)
    assert not rows["bielefeld-chairs"].present  # the folder lacks the 170 raw images
    assert rows["my-corridor"].location == "give --path"
    assert rows["synth-day"].kind == "generated" and not rows["synth-day"].present
    assert rows["synth-day"].location.startswith(str(clean_env / "data" / "synth" / "synth-day-"))
