"""Feature files that cannot execute code: ``.npz`` arrays (no pickles) plus a JSON structure.

A run folder is something people share, so reading one must never run code. What a method's
``describe`` returns is split into a JSON structure and the numpy arrays it holds:

- None, bool, int, float (NaN and infinities too) and str are JSON values; bytes, numpy arrays
  and numpy scalars are arrays (dtype kept; object arrays are refused);
- lists are JSON lists, tuples ``{"tuple": [...]}``, dicts ``{"dict": [[key, value], ...]}`` (any
  of these as keys);
- dataclasses ``{"dataclass": "module:Name", "fields": {...}}``, rebuilt only when the name is
  on the allowlist (homebench's own feature and geometry classes, and classes a plugin
  registers with :func:`homebench.methods.registry.register_features`). A name read from a file
  is never imported.

The file is an uncompressed npz: arrays ``a0``, ``a1``, ... and ``structure`` (the JSON text as
UTF-8 bytes), loaded with ``allow_pickle=False``. It also holds the feature key, so a file of
other inputs (or a torn, corrupt or crafted one) is refused and its features recomputed. A file
is read in an order that never inflates what it should not: its size, then the zip directory
(every member stored, as homebench writes them: a member's bytes are then its bytes in the
file), then the structure and its key, then each array's header against its member's size, and
only then the arrays.

A process keeps the files it read last in memory (:data:`RECENT_BYTES` of arrays, by path,
trusted while they hold the key asked for), since a run's home jobs read every current view's
features once per goal; their arrays are read-only, as they are shared by the calls.
"""

from __future__ import annotations

import dataclasses
import functools
import io
import json
import math
import os
import zipfile
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from homebench.errors import DataError
from homebench.fileio import make_folder, open_regular, write_bytes_atomic
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry
from homebench.methods import registry
from homebench.methods.klt_sector.method import KltFeatures
from homebench.methods.sift.method import SiftFeatures

FORMAT = 1
#: Bytes of feature arrays a process keeps from the files it read last.
RECENT_BYTES = 128 * 1024 * 1024
#: Largest feature file read (a method's features of one image are well under 100 MB) and
#: largest JSON structure in one.
MAX_FILE_BYTES = 1 << 30
MAX_STRUCTURE_BYTES = 64 << 20
#: homebench's own classes that features may hold.
BUILT_IN = (SiftFeatures, KltFeatures, PanoramaGeometry, CatadioptricGeometry)


@dataclass(frozen=True)
class StoredFeatures:
    """What a feature file holds: the method's features and the time ``describe`` took (ms;
    NaN for a process's first describe, see :func:`~homebench.evaluation.pair_calls.timed`)."""

    features: Any
    describe_ms: float


def _name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _allowed() -> dict[str, type]:
    return {_name(cls): cls for cls in (*BUILT_IN, *registry.feature_classes())}


class _Encoder:
    """Turns a value into a JSON structure, collecting its arrays."""

    def __init__(self) -> None:
        self.arrays: list[np.ndarray] = []
        self.allowed = _allowed()

    def array(self, value: np.ndarray, tag: str) -> dict[str, int]:
        if value.dtype.hasobject:
            raise DataError("features hold an array of Python objects (dtype object)")
        self.arrays.append(value)
        return {tag: len(self.arrays) - 1}

    def encode(self, value: Any) -> Any:
        if isinstance(value, np.ndarray | np.generic):  # before float: np.float64 is a float
            return self.array(
                np.asarray(value), "scalar" if isinstance(value, np.generic) else "array"
            )
        if value is None or isinstance(value, bool | int | float | str):
            return value
        if isinstance(value, bytes):
            return self.array(np.frombuffer(value, dtype=np.uint8), "bytes")
        if isinstance(value, list):
            return [self.encode(v) for v in value]
        if isinstance(value, tuple):
            return {"tuple": [self.encode(v) for v in value]}
        if isinstance(value, dict):
            return {"dict": [[self.encode(k), self.encode(v)] for k, v in value.items()]}
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            name = _name(type(value))
            if name not in self.allowed:
                raise DataError(
                    f"features of type {name} cannot be stored: register the class with "
                    "homebench.methods.registry.register_features"
                )
            fields = {
                f.name: self.encode(getattr(value, f.name)) for f in dataclasses.fields(value)
            }
            return {"dataclass": name, "fields": fields}
        raise DataError(f"features of type {type(value).__name__} cannot be stored")


class _Decoder:
    """Rebuilds a value from its JSON structure and arrays."""

    def __init__(self, arrays: dict[str, np.ndarray]):
        self.arrays = arrays

    @functools.cached_property  # only features that hold dataclasses ask (a warping pair's do not)
    def allowed(self) -> dict[str, type]:
        return _allowed()

    def decode(self, node: Any) -> Any:
        if isinstance(node, list):
            return [self.decode(v) for v in node]
        if not isinstance(node, dict):
            return node
        tags = set(node)
        if tags == {"array"}:
            return self.arrays[f"a{node['array']}"]
        if tags == {"scalar"}:
            return self.arrays[f"a{node['scalar']}"][()]
        if tags == {"bytes"}:
            return self.arrays[f"a{node['bytes']}"].tobytes()
        if tags == {"tuple"}:
            return tuple(self.decode(v) for v in node["tuple"])
        if tags == {"dict"}:
            return {_hashable(self.decode(k)): self.decode(v) for k, v in node["dict"]}
        if tags == {"dataclass", "fields"}:
            return self.dataclass(node["dataclass"], node["fields"])
        raise ValueError(f"unknown structure {sorted(tags)}")

    def dataclass(self, name: str, fields: dict[str, Any]) -> Any:
        cls = self.allowed.get(name)
        if cls is None:
            raise ValueError(f"class {name} is not allowed in feature files")
        values = {key: self.decode(value) for key, value in fields.items()}
        init = {f.name for f in dataclasses.fields(cls) if f.init}
        instance = cls(**{k: v for k, v in values.items() if k in init})
        for key in values.keys() - init:
            object.__setattr__(instance, key, values[key])
        return instance


def _hashable(key: Any) -> Any:
    if isinstance(key, list | dict | np.ndarray):
        raise ValueError("a dict key must be hashable")
    return key


def save_features(path: Path, key: str, features: Any, describe_ms: float) -> None:
    """Write ``features`` (and the time ``describe`` took) under ``key`` to ``path``,
    atomically; DataError for features that cannot be stored, WriteError for a file that
    cannot be written."""
    encoder = _Encoder()
    structure = {
        "format": FORMAT,
        "key": key,
        "describe_ms": None if math.isnan(describe_ms) else describe_ms,
        "features": encoder.encode(features),
    }
    arrays = {f"a{k}": array for k, array in enumerate(encoder.arrays)}
    arrays["structure"] = np.frombuffer(json.dumps(structure).encode(), dtype=np.uint8)
    buffer = io.BytesIO()
    np.savez(buffer, allow_pickle=False, **arrays)
    make_folder(path.parent)
    write_bytes_atomic(path, buffer.getvalue())


class _RecentFiles:
    """The structure and arrays of the feature files read last, at most ``limit`` bytes of
    arrays, by path. A file is read again unless its remembered structure holds the key asked
    for: a file written again under the same key holds the same features (the key holds
    everything that determines them), so a hit costs no system call (a ``stat`` per read was
    3 % of a warping run's CPU)."""

    def __init__(self, limit: int):
        self.limit, self.size = limit, 0
        self.files: OrderedDict[Path, tuple[dict[str, Any], dict[str, np.ndarray], int]] = (
            OrderedDict()
        )

    def read(
        self, path: Path, key: str, from_disk: bool
    ) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """The JSON structure and the arrays (read-only) of the feature file at ``path``,
        read from the file when ``from_disk``."""
        remembered = self.files.get(path)
        if remembered is not None:
            if not from_disk and remembered[0].get("key") == key:
                self.files.move_to_end(path)
                return remembered[0], remembered[1]
            self.size -= self.files.pop(path)[2]  # read again, or gone if that fails
        structure, arrays = _read_file(path, key)
        for array in arrays.values():
            array.flags.writeable = False
        nbytes = sum(array.nbytes for array in arrays.values())
        self.files[path] = (structure, arrays, nbytes)
        self.size += nbytes
        while self.size > self.limit:
            self.size -= self.files.popitem(last=False)[1][2]
        return structure, arrays


#: The readers of the .npy headers numpy writes, by version.
_NPY_HEADERS = {
    (1, 0): np.lib.format.read_array_header_1_0,
    (2, 0): np.lib.format.read_array_header_2_0,
}


def _read_file(path: Path, key: str) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The JSON structure and the arrays of the feature file at ``path`` if it holds the
    features of ``key`` (see the module docstring for the order of the checks); ValueError,
    OSError or zipfile.BadZipFile otherwise."""
    with open_regular(path) as f:
        if os.fstat(f.fileno()).st_size > MAX_FILE_BYTES:
            raise ValueError(f"larger than {MAX_FILE_BYTES:,} bytes")
        with zipfile.ZipFile(f) as archive:
            members = {m.filename.removesuffix(".npy"): m for m in archive.infolist()}
            packed = [m.filename for m in members.values() if m.compress_type != zipfile.ZIP_STORED]
            if packed:
                raise ValueError(f"{packed[0]} is compressed (homebench writes none)")
            if "structure" not in members:
                raise ValueError("no structure")
            text = _read_member(archive, members.pop("structure"), MAX_STRUCTURE_BYTES)
            structure = json.loads(text.tobytes())
            if not isinstance(structure, dict):
                raise ValueError("its structure is not a JSON object")
            if structure.get("format") != FORMAT or structure.get("key") != key:
                raise ValueError("written for other inputs")
            arrays = {name: _read_member(archive, m, MAX_FILE_BYTES) for name, m in members.items()}
    return structure, arrays


def _read_member(archive: zipfile.ZipFile, member: zipfile.ZipInfo, limit: int) -> np.ndarray:
    """The array of a stored ``.npy`` member of at most ``limit`` bytes, read once its header
    is found to describe exactly the member's bytes (a header may claim any shape)."""
    if member.file_size > limit:
        raise ValueError(f"{member.filename} is larger than {limit:,} bytes")
    with archive.open(member) as stream:
        read_header = _NPY_HEADERS.get(np.lib.format.read_magic(stream))
        if read_header is None:
            raise ValueError(f"{member.filename}: not a .npy file of version 1 or 2")
        shape, fortran, dtype = read_header(stream)
        if dtype.hasobject:
            raise ValueError(f"{member.filename} holds Python objects")
        size = math.prod(shape) * dtype.itemsize
        if stream.tell() + size != member.file_size:
            raise ValueError(f"{member.filename}: its header does not match its size")
        data = np.frombuffer(stream.read(size), dtype=dtype)
    return data.reshape(shape, order="F" if fortran else "C")


_RECENT = _RecentFiles(RECENT_BYTES)


def _time(value: Any) -> float:
    """A stored describe time: ms, or NaN where none was taken (null in the file)."""
    return math.nan if value is None else float(value)


def load_features(path: Path, key: str, from_disk: bool = False) -> StoredFeatures:
    """The features stored under ``key`` in ``path``; DataError naming the file when it is
    missing, corrupt, of another key or format, or holds anything but plain data. Features
    this process read before under ``key`` come from memory unless ``from_disk`` (which
    checks the file itself)."""
    try:
        structure, arrays = _RECENT.read(
            path if isinstance(path, Path) else Path(path), key, from_disk
        )
        features = _Decoder(arrays).decode(structure["features"])
        return StoredFeatures(features, _time(structure["describe_ms"]))
    except FileNotFoundError:
        raise DataError(f"{path}: feature file missing") from None
    except (
        OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError, MemoryError,
        zipfile.BadZipFile,
    ) as error:  # fmt: skip
        raise DataError(
            f"{path}: unusable feature file ({type(error).__name__}: {error})"
        ) from None
