"""homebench.fileio: atomic writes, deterministic PNG, checked reads, sha256."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from homebench.errors import CorruptImageError, DataError
from homebench.fileio import (
    atomic_directory,
    atomic_write,
    encode_png,
    read_grey,
    sha256_file,
    write_png,
    write_text_atomic,
)


def _image(seed: int = 0, shape: tuple[int, int] = (48, 64)) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, shape, dtype=np.uint8)


def test_atomic_write_replaces_the_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old")
    write_text_atomic(target, "new\n")
    assert target.read_text() == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    assert target.stat().st_mode & 0o777 == 0o666 & ~_umask()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@pytest.mark.parametrize("error", [RuntimeError("boom"), KeyboardInterrupt()])
def test_atomic_write_keeps_the_old_file_on_any_error(tmp_path: Path, error: BaseException) -> None:
    target = tmp_path / "a.bin"
    target.write_bytes(b"old")
    with pytest.raises(type(error)), atomic_write(target) as f:
        f.write(b"half of the new cont")
        raise error
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.bin"]


def test_atomic_write_of_a_new_file_leaves_nothing_on_error(tmp_path: Path) -> None:
    with pytest.raises(KeyboardInterrupt), atomic_write(tmp_path / "new.txt", "w") as f:
        f.write("partial")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_atomic_directory_appears_only_when_complete(tmp_path: Path) -> None:
    final = tmp_path / "db"
    with atomic_directory(final) as tmp:
        (tmp / "x.txt").write_text("x")
        assert not final.exists()
    assert (final / "x.txt").read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["db"]


def test_atomic_directory_is_removed_on_error(tmp_path: Path) -> None:
    final = tmp_path / "db"
    with pytest.raises(KeyboardInterrupt), atomic_directory(final) as tmp:
        (tmp / "x.txt").write_text("x")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_atomic_directory_refuses_to_replace_a_full_folder(tmp_path: Path) -> None:
    final = tmp_path / "db"
    final.mkdir()
    (final / "keep.txt").write_text("keep")
    with pytest.raises(DataError, match="db"), atomic_directory(final) as tmp:
        (tmp / "x.txt").write_text("x")
    assert sorted(p.name for p in final.iterdir()) == ["keep.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["db"]


def test_png_is_bit_identical_for_identical_pixels_and_round_trips(tmp_path: Path) -> None:
    image = _image()
    write_png(tmp_path / "a.png", image)
    write_png(tmp_path / "b.png", image.copy())
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    assert (tmp_path / "a.png").read_bytes() == encode_png(image)
    np.testing.assert_array_equal(read_grey(tmp_path / "a.png"), image)
    assert encode_png(_image(1)) != encode_png(image)


def test_read_grey_converts_colour_to_grey(tmp_path: Path) -> None:
    colour = np.dstack([_image(0), _image(1), _image(2)])
    write_png(tmp_path / "c.png", colour)
    grey = read_grey(tmp_path / "c.png")
    assert grey.shape == (48, 64)
    assert grey.dtype == np.uint8
    np.testing.assert_array_equal(grey, cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY))


def _truncated(ext: str) -> bytes:
    ok, buffer = cv2.imencode(ext, _image(shape=(120, 160)))
    assert ok
    return buffer.tobytes()[: buffer.size // 2]


@pytest.mark.parametrize(
    ("name", "content", "reason"),
    [
        ("empty.png", b"", "zero bytes"),
        ("cut.png", _truncated(".png"), "truncated"),
        ("cut.jpg", _truncated(".jpg"), "truncated"),
        ("cut.pgm", _truncated(".pgm"), "truncated"),
        ("text.png", b"this is not an image\n" * 10, "not an image"),
    ],
)
def test_read_grey_names_the_file_it_cannot_decode(
    tmp_path: Path, name: str, content: bytes, reason: str
) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(CorruptImageError, match=reason) as info:
        read_grey(path)
    assert str(path) in str(info.value)
    assert info.value.path == path


def test_read_grey_of_a_missing_file_names_it(tmp_path: Path) -> None:
    with pytest.raises(CorruptImageError, match="nope.png"):
        read_grey(tmp_path / "nope.png")


def test_sha256_file_matches_hashlib(tmp_path: Path) -> None:
    data = os.urandom(3_000_000)
    (tmp_path / "f").write_bytes(data)
    assert sha256_file(tmp_path / "f", chunk_size=1 << 16) == hashlib.sha256(data).hexdigest()


def test_read_grey_keeps_the_high_byte_of_16_bit_images(tmp_path: Path) -> None:
    image = _image().astype(np.uint16) * 256 + 7  # high byte: the 8-bit image
    cv2.imwrite(str(tmp_path / "deep.png"), image)
    np.testing.assert_array_equal(read_grey(tmp_path / "deep.png"), _image())


def test_a_result_record_larger_than_the_bound_is_not_read(tmp_path: Path, monkeypatch) -> None:
    """A run folder may come from someone else: a record file beyond MAX_RECORD_BYTES is
    treated as corrupt (recomputed, or reported as such) without reading it into memory."""
    import homebench.fileio as fileio
    from homebench.experiments.trials import TrialRecord, read_trial

    path = tmp_path / "trials" / "t.json"
    path.parent.mkdir()
    path.write_text('{"key": "k", "summary": {}, "pad": "' + "x" * 2000 + '"}')
    assert fileio.read_json_record(path, "k") is not None
    assert isinstance(read_trial(path, tmp_path, "t", "k", TrialRecord, {}), dict)
    monkeypatch.setattr(fileio, "MAX_RECORD_BYTES", 1000)
    assert fileio.read_json_record(path, "k") is None
    assert read_trial(path, tmp_path, "t", "k", TrialRecord, {}) == (
        "trials/t.json (trial t: corrupt, larger than 1000 bytes)"
    )
