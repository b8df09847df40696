"""File primitives: atomic writes, deterministic PNG, checked grey-image reads, sha256.

Everything homebench writes goes through :func:`atomic_write` (or :func:`atomic_directory` for a
folder built as a whole), so an interrupted program never leaves a half-written file under its
final name.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.errors import CorruptImageError, DataError

#: Fixed PNG settings: the same pixels always give the same bytes (for one libpng / zlib).
PNG_PARAMS = (
    cv2.IMWRITE_PNG_COMPRESSION,
    6,
    cv2.IMWRITE_PNG_STRATEGY,
    cv2.IMWRITE_PNG_STRATEGY_DEFAULT,
)


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Files and folders made through temporary names get the usual permissions, not mkstemp's 0600.
_UMASK = _current_umask()


def _fsync_directory(folder: Path) -> None:
    """Make a rename inside ``folder`` durable (a no-op where directories cannot be opened)."""
    flags = getattr(os, "O_DIRECTORY", None)
    if flags is None:
        return
    fd = os.open(folder, os.O_RDONLY | flags)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_write(path: Path, mode: str = "wb") -> Iterator[IO]:
    """Open a temporary file beside ``path``; on success fsync it and rename it to ``path``.

    On any exception (KeyboardInterrupt included) the temporary file is removed and the
    exception propagates; ``path`` is then untouched. An OS error (disk full, no permission)
    becomes a DataError naming ``path``. ``mode`` is "wb" or "w" (UTF-8 text).
    """
    if mode not in ("wb", "w"):
        raise ValueError(f"mode must be 'wb' or 'w', got {mode!r}")
    path = Path(path)
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as error:
        raise DataError(f"{path}: cannot write ({error.strerror or error})") from error
    tmp = Path(tmp_name)
    try:
        os.chmod(tmp, 0o666 & ~_UMASK)
        text = {} if mode == "wb" else {"encoding": "utf-8", "newline": "\n"}
        with os.fdopen(fd, mode, **text) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as error:
        tmp.unlink(missing_ok=True)
        raise DataError(f"{path}: cannot write ({error.strerror or error})") from error
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_directory(path.parent)


def write_bytes_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_write(path, "wb") as f:
        f.write(data)


def write_text_atomic(path: Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (newlines as "\\n")."""
    with atomic_write(path, "w") as f:
        f.write(text)


@contextlib.contextmanager
def atomic_directory(path: Path) -> Iterator[Path]:
    """Yield a temporary sibling folder of ``path``; rename it to ``path`` when the block ends.

    On any exception the temporary folder is removed and ``path`` is not created. Raises
    DataError if ``path`` appears meanwhile (another process finished first); the caller
    decides whether that folder is acceptable.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent))
    try:
        os.chmod(tmp, 0o777 & ~_UMASK)
        yield tmp
        try:
            os.rename(tmp, path)
        except OSError as error:
            raise DataError(f"{path}: cannot move the new folder into place ({error})") from error
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _fsync_directory(path.parent)


def encode_png(image: NDArray[np.uint8]) -> bytes:
    """PNG bytes of a grey (h, w) or BGR (h, w, 3) uint8 image with the fixed settings."""
    if image.dtype != np.uint8:
        raise ValueError(f"PNG images must be uint8, got {image.dtype}")
    ok, buffer = cv2.imencode(".png", np.ascontiguousarray(image), list(PNG_PARAMS))
    if not ok:
        raise ValueError(f"cannot encode an image of shape {image.shape} as PNG")
    return buffer.tobytes()


def write_png(path: Path, image: NDArray[np.uint8]) -> None:
    """Write ``image`` to ``path`` as PNG, atomically and deterministically."""
    write_bytes_atomic(path, encode_png(image))


def read_grey(path: Path) -> NDArray[np.uint8]:
    """Read an image file as grey levels, shape (height, width), uint8.

    Colour is converted with OpenCV's BGR -> grey weights whatever the file format, 16-bit
    images keep their high byte. Raises CorruptImageError naming the file for a missing,
    unreadable, zero-byte, truncated or non-image file.
    """
    path = Path(path)
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as error:
        raise CorruptImageError(path, f"cannot be read ({error.strerror or error})") from error
    if data.size == 0:
        raise CorruptImageError(path, "is empty (zero bytes)")
    try:
        image = cv2.imdecode(data, cv2.IMREAD_UNCHANGED)
    except cv2.error as error:
        raise CorruptImageError(path) from error
    if image is None or image.size == 0:
        raise CorruptImageError(path, "cannot be decoded as an image (truncated or not an image)")
    return _to_grey_uint8(image, path)


def _to_grey_uint8(image: NDArray, path: Path) -> NDArray[np.uint8]:
    """Grey uint8 (h, w) from a decoded grey, BGR or BGRA image of 8 or 16 bits."""
    if image.dtype == np.uint16:
        image = (image >> 8).astype(np.uint8)
    if image.dtype != np.uint8:
        raise CorruptImageError(path, f"has unsupported pixel type {image.dtype}")
    channels = 1 if image.ndim == 2 else image.shape[2]
    conversions = {1: None, 3: cv2.COLOR_BGR2GRAY, 4: cv2.COLOR_BGRA2GRAY}
    if channels not in conversions:
        raise CorruptImageError(path, f"has {channels} channels (expected 1, 3 or 4)")
    if conversions[channels] is None:
        return image.reshape(image.shape[:2])
    return cv2.cvtColor(image, conversions[channels])


def read_json_record(path: Path, key: str) -> dict[str, Any] | None:
    """The JSON object in ``path`` whose "key" is ``key``; None if the file is missing,
    unreadable, corrupt, or holds another key (so the caller recomputes it)."""
    try:
        record = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or record.get("key") != key:
        return None
    return record


def sha256_file(path: Path, chunk_size: int = 1 << 20) -> str:
    """Hex sha256 of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(chunk_size):
            digest.update(chunk)
    return digest.hexdigest()
