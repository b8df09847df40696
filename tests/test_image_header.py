"""Image sizes come from the file header and are checked before anything is decoded (issue 12):
a small file claiming a huge image is refused without allocating it."""

from __future__ import annotations

import os
import struct
import threading
import time
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from homebench import fileio
from homebench.cli import main
from homebench.errors import CorruptImageError, ImageSizeError
from homebench.fileio import check_image, read_grey
from homebench.image_header import read_header


def _encoded(ext: str, shape: tuple[int, ...] = (48, 64), dtype: type = np.uint8) -> bytes:
    image = np.random.default_rng(0).integers(0, 200, shape).astype(dtype)
    ok, buffer = cv2.imencode(ext, image)
    assert ok
    return buffer.tobytes()


def _header_of(tmp_path: Path, data: bytes) -> tuple[str, int, int]:
    path = tmp_path / "image"
    path.write_bytes(data)
    with open(path, "rb") as f:
        header = read_header(f, path)
    return header.format, header.width, header.height


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (_encoded(".png"), ("PNG", 64, 48)),
        (_encoded(".png", (48, 64, 3)), ("PNG", 64, 48)),
        (_encoded(".png", (48, 64), np.uint16), ("PNG", 64, 48)),
        (_encoded(".pgm"), ("PNM", 64, 48)),
        (_encoded(".ppm", (48, 64, 3)), ("PNM", 64, 48)),
        (b"P2\n# a comment\n 3 # width\n2\n255\n1 2 3\n4 5 6\n", ("PNM", 3, 2)),
        (b"P1 2 2 0101", ("PNM", 2, 2)),
        (_encoded(".jpg"), ("JPEG", 64, 48)),
        (_encoded(".jpg", (48, 64, 3)), ("JPEG", 64, 48)),
    ],
)
def test_sizes_are_read_from_the_header(
    tmp_path: Path, data: bytes, expected: tuple[str, int, int]
) -> None:
    assert _header_of(tmp_path, data) == expected


def _png_claiming(width: int, height: int) -> bytes:
    """A real PNG whose IHDR (with a valid CRC) claims ``width`` x ``height``."""
    data = bytearray(_encoded(".png"))
    ihdr = bytes(data[12:16]) + struct.pack(">II", width, height) + bytes(data[24:29])
    data[16:24] = struct.pack(">II", width, height)
    data[29:33] = struct.pack(">I", zlib.crc32(ihdr))
    return bytes(data)


def _jpeg_claiming(width: int, height: int) -> bytes:
    data = bytearray(_encoded(".jpg"))
    sof = data.index(b"\xff\xc0")
    data[sof + 5 : sof + 9] = struct.pack(">HH", height, width)
    return bytes(data)


CLAIMING_30000 = {
    "png": _png_claiming(30000, 30000),
    "pgm": b"P5\n30000 30000\n255\n" + bytes(1000),
    "jpg": _jpeg_claiming(30000, 30000),
}


@pytest.fixture
def decoded(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The byte counts of every buffer handed to OpenCV's decoder during the test."""
    calls: list[int] = []
    real = cv2.imdecode

    def spy(data: np.ndarray, flags: int) -> np.ndarray | None:
        calls.append(len(data))
        return real(data, flags)

    monkeypatch.setattr(cv2, "imdecode", spy)
    return calls


@pytest.mark.parametrize("ext", sorted(CLAIMING_30000))
def test_a_huge_image_is_refused_before_decoding(
    tmp_path: Path, ext: str, decoded: list[int]
) -> None:
    path = tmp_path / f"bomb.{ext}"
    path.write_bytes(CLAIMING_30000[ext])
    with pytest.raises(ImageSizeError, match=r"is 30000x30000 .*expected 64x48") as info:
        read_grey(path, (64, 48))
    assert info.value.path == path and str(path) in str(info.value)
    with pytest.raises(ImageSizeError):
        check_image(path, (64, 48))
    assert decoded == []


def test_without_an_expected_size_the_pixel_cap_applies(tmp_path: Path, decoded: list[int]) -> None:
    path = tmp_path / "bomb.png"
    path.write_bytes(CLAIMING_30000["png"])
    with pytest.raises(CorruptImageError, match=r"30000x30000, more than"):
        read_grey(path)
    assert decoded == []


def test_a_database_refuses_a_decompression_bomb_by_its_header(
    tmp_path: Path, decoded: list[int]
) -> None:
    from test_database import make_user_database

    root = make_user_database(tmp_path / "db")
    bomb = root / "pano" / "img-001-001.png"
    bomb.write_bytes(_png_claiming(30000, 30000))
    result = CliRunner().invoke(main, ["data", "verify", str(root), "--path", str(root)])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [
        f"homebench: error: {bomb}: image is 30000x30000 (width x height), expected 40x12"
    ]
    assert bomb.stat().st_size not in decoded


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (_encoded(".bmp"), "not an image homebench reads"),
        (_encoded(".png")[:20], "truncated"),
        (_encoded(".png")[:-12], "truncated"),
        (_encoded(".pgm")[:-1], "truncated"),
        (_encoded(".jpg")[:3], "truncated"),
        (b"\xff\xd8\xff\xda\x00\x02", "no JPEG frame header"),
        (b"P5\n99999999999 2\n255\n", "PNM header"),
    ],
)
def test_a_bad_header_is_a_corrupt_image_without_decoding(
    tmp_path: Path, data: bytes, reason: str, decoded: list[int]
) -> None:
    path = tmp_path / "bad.img"
    path.write_bytes(data)
    with pytest.raises(CorruptImageError, match=reason) as info:
        check_image(path, (64, 48))
    assert info.value.path == path
    assert decoded == []


def test_a_file_far_larger_than_its_image_is_not_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, decoded: list[int]
) -> None:
    monkeypatch.setattr(fileio, "IMAGE_EXTRA_BYTES", 1000)
    path = tmp_path / "padded.pgm"
    path.write_bytes(b"P5\n64 48\n255\n" + bytes(64 * 48 * 40))
    with pytest.raises(CorruptImageError, match="too large for a 64x48 image"):
        read_grey(path, (64, 48))
    assert decoded == []


def test_a_fifo_is_refused_without_waiting(tmp_path: Path) -> None:
    fifo = tmp_path / "0_0.png"
    os.mkfifo(fifo)

    def writer() -> None:  # lets a blocking reader go on, so that the test never hangs
        with open(fifo, "wb"):
            pass

    threading.Thread(target=writer, daemon=True).start()
    start = time.monotonic()
    with pytest.raises(CorruptImageError, match="not a regular file"):
        read_grey(fifo)
    assert time.monotonic() - start < 5


def test_decoding_still_gives_grey_images_of_the_header_size(tmp_path: Path) -> None:
    path = tmp_path / "c.jpg"
    path.write_bytes(_encoded(".jpg", (48, 64, 3)))
    grey = read_grey(path, (64, 48))
    assert grey.shape == (48, 64) and grey.dtype == np.uint8
