"""File primitives: atomic writes, deterministic PNG, checked grey-image reads, sha256.

Everything homebench writes goes through :func:`atomic_write` (or :func:`atomic_directory` for a
folder built as a whole), so an interrupted program never leaves a half-written file under its
final name; what a killed one leaves under a temporary name is removed by the next
(:mod:`homebench.orphans`). Images are checked by their header before they are decoded
(:mod:`homebench.image_header`), and only regular files are read (:func:`open_regular`).
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, BinaryIO

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.errors import (
    CorruptImageError,
    DataError,
    HomebenchError,
    ImageSizeError,
    WriteError,
)
from homebench.image_header import MAX_IMAGE_PIXELS, ImageHeader, read_header, truncation
from homebench.orphans import TMP_SUFFIX, lock, locked_folder, sweep_once

#: Fixed PNG settings: the same pixels always give the same bytes (for one libpng / zlib).
PNG_PARAMS = (
    cv2.IMWRITE_PNG_COMPRESSION,
    6,
    cv2.IMWRITE_PNG_STRATEGY,
    cv2.IMWRITE_PNG_STRATEGY_DEFAULT,
)


#: An image file may hold at most this many bytes per pixel of the size its header gives, plus
#: IMAGE_EXTRA_BYTES (metadata), before it is read whole: an ASCII PPM of 16-bit colour needs
#: 18 bytes per pixel, compressed formats fewer.
IMAGE_BYTES_PER_PIXEL = 32
IMAGE_EXTRA_BYTES = 16 << 20

_FILE_KINDS = {
    stat.S_ISDIR: "a folder",
    stat.S_ISFIFO: "a FIFO",
    stat.S_ISCHR: "a character device",
    stat.S_ISBLK: "a block device",
    stat.S_ISSOCK: "a socket",
}


def _file_kind(mode: int) -> str:
    """What a file of ``mode`` (``st_mode``) that is no regular file is: "a folder", ..."""
    return next((k for test, k in _FILE_KINDS.items() if test(mode)), "a special file")


class NotRegularFileError(OSError):
    """A path that names a folder, FIFO, device or socket where a regular file is needed."""

    def __init__(self, path: Path, mode: int):
        super().__init__(errno.EINVAL, f"not a regular file: {_file_kind(mode)}", str(path))


def file_problem(path: Path, what: str) -> str:
    """Why ``path``, which is there, holds no ``what`` ("image") to read: "the image is a
    folder, not a file" (a FIFO, a device, ...), "cannot open the image (Too many levels of
    symbolic links)"; "" when it is a regular file, or when nothing is there (no file, or a
    symbolic link to none: missing)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return ""
    except OSError as error:
        return f"cannot open the {what} ({error.strerror or error})"
    return "" if stat.S_ISREG(mode) else f"the {what} is {_file_kind(mode)}, not a file"


def open_regular(path: Path) -> BinaryIO:
    """Open ``path`` for binary reading if it is a regular file; OSError otherwise.

    The file is opened without blocking (a FIFO without a writer would wait for ever) and its
    kind checked on the open descriptor (no race with a swapped path), so nothing is ever read
    from a FIFO, a device such as /dev/zero, or a folder (NotRegularFileError).
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise NotRegularFileError(Path(path), mode)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_small_text(
    path: Path, limit: int, what: str, error: type[HomebenchError] = DataError
) -> str:
    """The UTF-8 text (a leading byte-order mark dropped) of the regular file ``path`` of at
    most ``limit`` bytes; ``error`` naming the file and the ``what`` otherwise: missing,
    unreadable, too large or not UTF-8 (nothing is read from a FIFO, a device or a folder:
    :func:`open_regular`)."""
    try:
        with open_regular(path) as f:
            data = f.read(limit + 1)
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as problem:
        raise error(f"{path}: cannot read the {what} ({problem.strerror or problem})") from None
    if len(data) > limit:
        raise error(f"{path}: the {what} is larger than the {size_text(limit)} limit")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as problem:
        raise error(f"{path}: the {what} is not UTF-8 text ({problem})") from None


def size_text(n_bytes: int) -> str:
    """A size limit as people read it: "16 MiB"."""
    return f"{n_bytes / (1 << 20):g} MiB"


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
    becomes a WriteError naming ``path``. ``mode`` is "wb" or "w" (UTF-8 text). The temporary
    file is locked until it is renamed (see homebench.orphans).
    """
    if mode not in ("wb", "w"):
        raise ValueError(f"mode must be 'wb' or 'w', got {mode!r}")
    path = Path(path)
    try:
        sweep_once(path.parent)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX, dir=path.parent)
    except OSError as error:
        raise WriteError(f"{path}: cannot write ({error.strerror or error})") from error
    tmp = Path(tmp_name)
    try:
        lock(fd)
        os.chmod(tmp, 0o666 & ~_UMASK)
        text = {} if mode == "wb" else {"encoding": "utf-8", "newline": "\n"}
        with os.fdopen(fd, mode, **text) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
            os.replace(tmp, path)  # before the file is closed: its lock is held until renamed
    except OSError as error:
        tmp.unlink(missing_ok=True)
        raise WriteError(f"{path}: cannot write ({error.strerror or error})") from error
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_directory(path.parent)


def make_folder(path: Path) -> Path:
    """Create the folder ``path`` and its parents where missing; ``path``. WriteError naming
    the path when that fails: "runs/x: is a file, not a folder", "runs/x: cannot create the
    folder (No space left on device)"."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        blocker = next((p for p in (path, *path.parents) if p.is_file()), path)
        raise WriteError(f"{blocker}: is a file, not a folder") from None
    except OSError as error:
        raise WriteError(f"{path}: cannot create the folder ({error.strerror or error})") from None
    return path


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
    decides whether that folder is acceptable. The temporary folder is locked until it is
    renamed or removed, so that no other process takes it for an orphan (homebench.orphans).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sweep_once(path.parent)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX, dir=path.parent))
    with locked_folder(tmp):
        try:
            os.chmod(tmp, 0o777 & ~_UMASK)
            yield tmp
            try:
                os.rename(tmp, path)
            except OSError as error:
                raise DataError(
                    f"{path}: cannot move the new folder into place ({error})"
                ) from error
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


@contextlib.contextmanager
def _checked_image(
    path: Path, size: tuple[int, int] | None
) -> Iterator[tuple[BinaryIO, ImageHeader]]:
    """The open image file and its header, checked before anything is decoded.

    The file must be a regular, non-empty file in a format whose header gives its size (see
    homebench.image_header), of ``size`` (width, height) if given, at most MAX_IMAGE_PIXELS,
    not far larger than such an image can be, and not visibly cut short. Raises
    CorruptImageError or ImageSizeError naming the file; an OSError while the caller reads
    becomes a CorruptImageError too.
    """
    path = Path(path)
    try:
        with open_regular(path) as f:
            n_bytes = os.fstat(f.fileno()).st_size
            if n_bytes == 0:
                raise CorruptImageError(path, "is empty (zero bytes)")
            header = read_header(f, path)
            width, height = header.width, header.height
            if size is not None and (width, height) != tuple(size):
                raise ImageSizeError(path, (size[0], size[1]), (width, height))
            if width * height > MAX_IMAGE_PIXELS:
                raise CorruptImageError(
                    path, f"is {width}x{height}, more than the {MAX_IMAGE_PIXELS:,} pixels allowed"
                )
            if n_bytes > IMAGE_BYTES_PER_PIXEL * width * height + IMAGE_EXTRA_BYTES:
                raise CorruptImageError(
                    path, f"is {n_bytes:,} bytes, too large for a {width}x{height} image"
                )
            problem = truncation(f, header, n_bytes)
            if problem is not None:
                raise CorruptImageError(path, problem)
            f.seek(0)
            yield f, header
    except OSError as error:
        raise CorruptImageError(path, f"cannot be read ({error.strerror or error})") from error


def check_image(path: Path, size: tuple[int, int] | None = None) -> ImageHeader:
    """Check an image file without decoding it (see :func:`read_grey`); return its header."""
    with _checked_image(path, size) as (_, header):
        return header


def read_grey(path: Path, size: tuple[int, int] | None = None) -> NDArray[np.uint8]:
    """Read an image file as grey levels, shape (height, width), uint8.

    The header is read first: an image whose size is not ``size`` (width, height) raises
    ImageSizeError before anything is decoded, and so does a format whose size cannot be read
    from its header (only PNG, PNM and JPEG are read). Colour is converted with OpenCV's BGR ->
    grey weights whatever the file format, 16-bit images keep their high byte. Raises
    CorruptImageError naming the file for a missing, unreadable, zero-byte, truncated or
    non-image file.
    """
    path = Path(path)
    with _checked_image(path, size) as (f, header):
        data = np.frombuffer(f.read(), dtype=np.uint8)
    try:
        image = cv2.imdecode(data, cv2.IMREAD_UNCHANGED)
    except cv2.error as error:
        raise CorruptImageError(path) from error
    if image is None or image.size == 0:
        raise CorruptImageError(path, "cannot be decoded as an image (truncated or not an image)")
    if (image.shape[1], image.shape[0]) != (header.width, header.height):
        raise CorruptImageError(
            path,
            f"decodes to {image.shape[1]}x{image.shape[0]} but its header says "
            f"{header.width}x{header.height}",
        )
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


#: Largest result record (bytes) read from a run folder; larger files count as corrupt. A grid
#: job's record or a robot trial's is well under 1 MB; a run folder may come from anyone.
MAX_RECORD_BYTES = 64 << 20


def read_record_text(path: Path, limit: int | None = None) -> str:
    """The text of a result record; ValueError when it is larger than ``limit`` bytes (default
    :data:`MAX_RECORD_BYTES`; checked before reading), OSError when it cannot be read."""
    limit = MAX_RECORD_BYTES if limit is None else limit
    size = Path(path).stat().st_size
    if size > limit:
        raise ValueError(f"larger than {limit} bytes")
    return Path(path).read_text(encoding="utf-8")


def parse_json(text: str | bytes) -> Any:
    """The value of the JSON ``text``; ValueError when it is not JSON (or nested too deeply for
    the parser: a file of 100,000 ``[`` is no crash)."""
    try:
        return json.loads(text)
    except RecursionError:
        raise ValueError("JSON nested too deeply") from None


def read_json_record(path: Path, key: str) -> dict[str, Any] | None:
    """The JSON object in ``path`` whose "key" is ``key``; None if the file is missing,
    unreadable, corrupt, too large, or holds another key (so the caller recomputes it)."""
    try:
        record = parse_json(read_record_text(path))
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
