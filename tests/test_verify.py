"""homebench.data.verify: a folder against its manifest, and recording sums into a manifest."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from test_database import make_user_database
from test_generate import FakeRenderer, small_spec

from homebench.data.catalog import resolve
from homebench.data.generate import generate, manifest_for_spec
from homebench.data.manifest import load_manifest
from homebench.data.verify import record_sums, verify
from homebench.errors import (
    ChecksumMismatchError,
    ConfigError,
    CorruptImageError,
    DataError,
    ImageSizeError,
    MissingImagesError,
)
from homebench.fileio import sha256_file, write_png


@pytest.fixture
def generated(tmp_path: Path) -> Path:
    return generate(small_spec(seed=2), tmp_path / "gen", 1, "tiny", renderer=FakeRenderer())


def test_a_fresh_generation_verifies_completely(generated: Path) -> None:
    report = verify(generated)
    assert report.name == "tiny" and report.root == generated
    assert len(report.checked) == 24 and report.n_images == 24
    assert report.unchecked == () and report.warnings == ()


def test_a_changed_file_names_file_expected_and_found(generated: Path) -> None:
    path = generated / "unfolded" / "1_2.png"
    expected = load_manifest(generated / "manifest.yaml").section("unfolded").files["1_2.png"]
    spec = small_spec(seed=2)
    write_png(path, np.zeros((spec.unfolded.height, spec.unfolded.width), np.uint8))
    found = sha256_file(path)
    with pytest.raises(ChecksumMismatchError) as info:
        verify(generated)
    message = str(info.value)
    assert str(path) in message and expected[:12] in message and found[:12] in message
    assert info.value.mismatches == [(path, expected, found)]


def test_several_changed_files_are_all_reported(generated: Path) -> None:
    for name in ("0_0.png", "2_3.png"):
        (generated / "raw" / name).write_bytes(b"junk")
    with pytest.raises(ChecksumMismatchError, match=r"and 1 more") as info:
        verify(generated)
    assert [p.name for p, _, _ in info.value.mismatches] == ["0_0.png", "2_3.png"]


def test_extra_files_are_warnings_not_errors(generated: Path) -> None:
    (generated / "notes.txt").write_text("hello")
    (generated / "raw" / "7_7.png").write_bytes(b"x")
    report = verify(generated)
    assert report.warnings == (
        f"{generated}: 1 unrelated files: notes.txt",
        f"{generated}: 1 raw images of positions outside the grid: raw/7_7.png",
    )
    assert len(report.checked) == 24


def test_many_extra_files_make_one_summary_line(generated: Path) -> None:
    for k in range(130):
        (generated / f"thumb_{k:03d}.jpg").write_bytes(b"x")
    (report_line,) = verify(generated).warnings
    assert "130 unrelated files: thumb_000.jpg, thumb_001.jpg, thumb_002.jpg and 127 more" in (
        report_line
    )


def test_bytes_that_differ_within_the_fingerprint_tolerance_are_reported_not_failed(
    generated: Path,
) -> None:
    """Another processor's rounding: a few pixels one grey level off. The sha256 differs, the
    content fingerprint matches: within tolerance. Content that really differs fails."""
    from homebench.fileio import read_grey

    path = generated / "unfolded" / "1_2.png"
    image = read_grey(path)
    flipped = image.copy().ravel()
    flipped[::997] = np.clip(flipped[::997].astype(int) + 1, 0, 255)
    write_png(path, flipped.reshape(image.shape))
    report = verify(generated)
    assert report.within_tolerance == ("unfolded/1_2.png",) and len(report.checked) == 24
    write_png(path, np.roll(image, 5, axis=1))  # the same content, turned 5 columns
    with pytest.raises(ChecksumMismatchError, match="1_2.png"):
        verify(generated)


def test_missing_images_are_named(generated: Path) -> None:
    (generated / "raw" / "1_3.png").unlink()
    with pytest.raises(MissingImagesError, match=r"\(1,3\)"):
        verify(generated)


def test_missing_or_broken_ground_truth(generated: Path) -> None:
    (generated / "ground_truth.json").write_text("{not json")
    with pytest.raises(DataError, match=r"ground_truth\.json: .*not valid JSON"):
        verify(generated)
    (generated / "ground_truth.json").unlink()
    with pytest.raises(DataError, match=r"ground_truth\.json: cannot read"):
        verify(generated)


def test_user_database_without_sums_verifies_as_unchecked(tmp_path: Path) -> None:
    """A user's own grid (3 x 2, 0.25 m, zero-padded names, unfolded only) loads and verifies."""
    root = make_user_database(tmp_path / "corridor")
    (root / "README").write_text("my corridor")
    report = verify(resolve(root))
    assert report.checked == ()
    assert report.unchecked == tuple(
        f"pano/img-{i:03d}-{j:03d}.png" for i in range(3) for j in range(2)
    )
    assert report.warnings == (f"{root}: 1 unrelated files: README",)


def test_unknown_sums_still_get_decoded_and_size_checked(tmp_path: Path) -> None:
    root = make_user_database(tmp_path / "corridor")
    (root / "pano" / "img-002-000.png").write_bytes(b"")
    with pytest.raises(CorruptImageError, match=r"img-002-000\.png: is empty"):
        verify(root)
    write_png(root / "pano" / "img-002-000.png", np.zeros((13, 40), np.uint8))
    with pytest.raises(ImageSizeError, match=r"img-002-000\.png"):
        verify(root)


def test_record_sums_then_verify_checks_every_file(tmp_path: Path) -> None:
    root = make_user_database(tmp_path / "corridor")
    manifest = record_sums(root / "manifest.yaml", root)
    assert len(manifest.section("unfolded").files) == 6
    assert load_manifest(root / "manifest.yaml") == manifest
    report = verify(root)
    assert len(report.checked) == 6 and report.unchecked == ()
    write_png(root / "pano" / "img-000-000.png", np.ones((12, 40), np.uint8))
    with pytest.raises(ChecksumMismatchError, match=r"img-000-000\.png"):
        verify(root)


def test_record_sums_into_a_shipped_style_manifest(generated: Path, tmp_path: Path) -> None:
    spec = small_spec(seed=2)
    shipped = tmp_path / "synth-tiny.yaml"
    shipped.write_text(manifest_for_spec(spec, "tiny").to_yaml())
    assert verify(generated, shipped).unchecked  # no sums yet
    record_sums(shipped, generated)
    assert load_manifest(shipped) == load_manifest(generated / "manifest.yaml")
    other = generate(small_spec(seed=4), tmp_path / "other", 1, "tiny", renderer=FakeRenderer())
    with pytest.raises(DataError, match="not a finished generation"):
        record_sums(shipped, other)


def test_stale_renderer_key_is_a_warning(generated: Path) -> None:
    text = (generated / "manifest.yaml").read_text()
    key = small_spec(seed=2).key()
    (generated / "manifest.yaml").write_text(text.replace(key, "0123456789abcdef"))
    report = verify(generated)
    assert any("0123456789abcdef" in w and key in w for w in report.warnings)


def test_verify_a_database_against_another_manifest(generated: Path, tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(generated, copy)
    (copy / "manifest.yaml").unlink()
    with pytest.raises(ConfigError, match="manifest.yaml"):
        verify(copy)
    report = verify(copy, generated / "manifest.yaml")
    assert len(report.checked) == 24


def test_a_folder_that_does_not_exist(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="no such database folder"):
        verify(tmp_path / "nowhere")
