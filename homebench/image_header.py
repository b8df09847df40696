"""Image sizes from file headers, read before anything is decoded.

A small file can claim a huge image (an 876 KB PNG of 30000 x 30000 decodes to 900 MB), so an
image's width and height are read from its header and checked before OpenCV may decode it.
Known formats, recognised by their first bytes whatever the file's extension: PNG (the IHDR
chunk), PNM (PBM / PGM / PPM, ASCII and binary: P1-P6) and JPEG (the SOFn frame header). Any
other format is refused, because its decoded size cannot be known without decoding it.

:func:`truncation` is a cheap completeness check (a PNG must end with its IEND chunk, a binary
PNM must hold the pixel bytes its header promises); other damage shows when decoding.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO, Literal

from homebench.errors import CorruptImageError

#: Largest image homebench decodes (64 Mpx, 64 MB grey; homebench's panoramas are well below
#: 1 Mpx): a manifest may not declare more, nor a header claim more when no size is expected.
MAX_IMAGE_PIXELS = 1 << 26

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"  # the IEND chunk: length 0, type, CRC
#: Longest PNM header read (comments included) and the prefix of a JPEG searched for its frame
#: header (EXIF, ICC and XMP segments come first; each is at most 64 KiB).
PNM_HEADER_BYTES = 16 << 10
JPEG_HEADER_BYTES = 4 << 20
#: JPEG markers starting a frame header (SOF0-SOF15 but DHT, JPG and DAC).
_JPEG_FRAMES = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}
#: JPEG markers without a length: TEM, RST0-RST7 and SOI.
_JPEG_BARE = frozenset([0x01, *range(0xD0, 0xD8), 0xD8])
_PNM_SPACE = re.compile(rb"(?:\s|#[^\r\n]*)*")  # whitespace and comments between the fields
_PNM_NUMBER = re.compile(rb"\d+")


def size_problem(width: int, height: int) -> str:
    """Why a ``width`` x ``height`` image is too large: more than :data:`MAX_IMAGE_PIXELS`
    (every image homebench generates, unfolds or reads is held to it); "" when it is not."""
    if width * height <= MAX_IMAGE_PIXELS:
        return ""
    return f"a {width} x {height} image has more than the {MAX_IMAGE_PIXELS:,} pixels allowed"


@dataclass(frozen=True)
class ImageHeader:
    """What a header says: the format, the size and, for a binary PNM, the pixel bytes' end."""

    format: Literal["PNG", "PNM", "JPEG"]
    width: int
    height: int
    end: int = 0  # least bytes of a complete file, where the header tells (binary PNM)


def read_header(f: BinaryIO, path: Path) -> ImageHeader:
    """The header of the image file open as ``f`` (at its start); CorruptImageError naming
    ``path`` if the file is not a PNG, PNM or JPEG image or its header is cut or invalid."""
    start = f.read(8)
    if start.startswith(PNG_SIGNATURE):
        return _png(f, path)
    if re.fullmatch(rb"P[1-6]\s", start[:3]):
        return _pnm(start + f.read(PNM_HEADER_BYTES), path)
    if start.startswith(b"\xff\xd8"):
        f.seek(2)
        return _jpeg(f, path)
    raise CorruptImageError(path, "is not an image homebench reads (PNG, PGM/PPM/PBM or JPEG)")


def truncation(f: BinaryIO, header: ImageHeader, n_bytes: int) -> str | None:
    """Why the ``n_bytes`` long file ``f`` is cut short, or None if no cheap check sees it."""
    if header.format == "PNG":
        f.seek(max(0, n_bytes - len(PNG_END)))
        if f.read() != PNG_END:
            return "is truncated (it does not end with the PNG IEND chunk)"
    if n_bytes < header.end:
        return f"is truncated ({n_bytes:,} bytes, its PNM header needs {header.end:,})"
    return None


def _truncated(path: Path, what: str) -> CorruptImageError:
    return CorruptImageError(path, f"is truncated (the {what} is cut short)")


def _png(f: BinaryIO, path: Path) -> ImageHeader:
    """Width and height from the IHDR chunk, the first after the signature."""
    chunk = f.read(16)
    if len(chunk) < 16:
        raise _truncated(path, "PNG header")
    if chunk[4:8] != b"IHDR":
        raise CorruptImageError(path, "is not a valid PNG (its first chunk is not IHDR)")
    width, height = struct.unpack(">II", chunk[8:16])
    return ImageHeader("PNG", width, height)


def _pnm(data: bytes, path: Path) -> ImageHeader:
    """Width, height (and maxval) after the magic number, between whitespace and comments."""
    kind = data[1] - ord("0")
    values, position = [], 2
    for _ in range(2 if kind in (1, 4) else 3):  # P1 and P4 (bitmaps) have no maxval
        position = _PNM_SPACE.match(data, position).end()
        number = _PNM_NUMBER.match(data, position)
        if number is None or len(number[0]) > 9:
            reason = "is cut short" if position >= len(data) else "is invalid"
            raise CorruptImageError(path, f"has a PNM header that {reason}")
        values.append(int(number[0]))
        position = number.end()
    width, height = values[:2]
    end = 0
    if kind >= 4:  # binary: one whitespace character, then exactly the pixel bytes
        depth = 1 if kind == 4 or values[2] < 256 else 2
        row = (width + 7) // 8 if kind == 4 else width * depth * (3 if kind == 6 else 1)
        end = position + 1 + row * height
    return ImageHeader("PNM", width, height, end)


def _jpeg(f: BinaryIO, path: Path) -> ImageHeader:
    """Width and height from the first frame header (SOFn), skipping the segments before it."""
    while f.tell() < JPEG_HEADER_BYTES:
        prefix, code = f.read(1), f.read(1)
        while code == b"\xff":  # fill bytes
            code = f.read(1)
        if not code:
            raise _truncated(path, "JPEG header")
        if prefix != b"\xff":
            raise CorruptImageError(path, "is not a valid JPEG (a marker was expected)")
        marker = code[0]
        if marker in _JPEG_BARE:
            continue
        if marker in (0xD9, 0xDA):  # end of image, or image data before any frame header
            break
        length = f.read(2)
        if len(length) < 2:
            raise _truncated(path, "JPEG header")
        segment = struct.unpack(">H", length)[0]
        if segment < 2:  # a segment's length counts its own two bytes
            raise CorruptImageError(path, "is not a valid JPEG (a segment length below 2)")
        if marker in _JPEG_FRAMES:
            frame = f.read(5)
            if len(frame) < 5:
                raise _truncated(path, "JPEG frame header")
            height, width = struct.unpack(">HH", frame[1:5])
            return ImageHeader("JPEG", width, height)
        f.seek(segment - 2, 1)
    raise CorruptImageError(path, "has no JPEG frame header before its image data")
