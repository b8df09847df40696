"""Feature files cannot execute code: npz without pickles plus a JSON structure; dataclasses
come back only from an allowlist. A corrupt or unsafe feature file is recomputed."""

from __future__ import annotations

import io
import json
import math
import os
import pickle
import tracemalloc
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import arena_config, run_config

from homebench.errors import DataError
from homebench.evaluation.features_io import load_features, save_features
from homebench.evaluation.jobs import _has_features
from homebench.geometry import PanoramaGeometry
from homebench.hashing import stable_hash
from homebench.methods.klt_sector.method import KltFeatures
from homebench.methods.sift.method import SiftFeatures


class _Marker:
    """Unpickling this creates a marker file: proof that a pickle was executed."""

    def __init__(self, path: Path):
        self.path = path

    def __reduce__(self) -> tuple:
        return (os.system, (f"touch {self.path}",))


def _same(a: object, b: object) -> None:
    assert type(a) is type(b)
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)
    elif isinstance(a, list | tuple):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _same(x, y)
    elif isinstance(a, dict):
        assert list(a) == list(b)
        for key in a:
            _same(a[key], b[key])
    elif hasattr(a, "__dataclass_fields__"):
        for name in a.__dataclass_fields__:
            _same(getattr(a, name), getattr(b, name))
    elif isinstance(a, float) and math.isnan(a):
        assert math.isnan(b)
    else:
        assert a == b


GEOMETRY = PanoramaGeometry.square_pixels(64, 0.7, -0.8)
VALUES = [
    np.arange(12, dtype=np.float32).reshape(3, 4),
    np.float32(2.5),
    np.int64(7),
    3,
    -1.5,
    math.nan,
    math.inf,
    True,
    None,
    "text",
    b"bytes",
    (1, "a", None),
    [np.zeros(3, dtype=np.uint8), [1, 2]],
    {"a": 1, "b": (2, 3), 4: "int key", (5, 6): "tuple key"},
    SiftFeatures(
        np.zeros((2, 2), np.float32),
        np.ones((2, 128), np.float32),
        np.array([0.1, 0.2]),
        np.array([1, -1], np.int8),
        period=64.0,
    ),
    KltFeatures(np.full((8, 64), 7, np.uint8), GEOMETRY, np.zeros((0, 2), np.float32), "d1"),
    GEOMETRY,
]


@pytest.mark.parametrize("value", VALUES, ids=[type(v).__name__ for v in VALUES])
def test_features_round_trip(tmp_path: Path, value: object) -> None:
    path = tmp_path / "f.npz"
    save_features(path, "key1", value, describe_ms=1.5)
    loaded = load_features(path, "key1")
    _same(loaded.features, value)
    assert loaded.describe_ms == 1.5


@dataclass(frozen=True)
class Unregistered:
    value: int


def test_unregistered_dataclasses_and_object_arrays_are_refused(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="register_features"):
        save_features(tmp_path / "a.npz", "k", Unregistered(1), describe_ms=0.0)
    with pytest.raises(DataError, match="object"):
        save_features(tmp_path / "b.npz", "k", np.array([None, 1], dtype=object), 0.0)
    assert list(tmp_path.iterdir()) == []


def test_unsafe_corrupt_or_foreign_files_do_not_load(tmp_path: Path) -> None:
    marker = tmp_path / "executed"
    unsafe = tmp_path / "unsafe.npz"
    np.savez(unsafe, structure=np.array([_Marker(marker)], dtype=object))
    corrupt = tmp_path / "corrupt.npz"
    save_features(corrupt, "k", np.zeros(100), 0.0)
    corrupt.write_bytes(corrupt.read_bytes()[:150])
    foreign = tmp_path / "foreign.npz"
    save_features(foreign, "other key", 1.0, 0.0)
    for path in (unsafe, corrupt, foreign, tmp_path / "missing.npz"):
        with pytest.raises(DataError, match=path.name):
            load_features(path, "k")
    assert not marker.exists()


def test_features_read_before_come_from_memory_and_a_check_reads_the_file(
    tmp_path: Path,
) -> None:
    """A process trusts features it read under a key (a run's home jobs read each current's
    once per goal, without a system call); ``from_disk`` (describe's check) reads the file."""
    path = tmp_path / "f.npz"
    save_features(path, "key1", np.arange(3.0), describe_ms=1.0)
    first = load_features(path, "key1")
    path.unlink()
    assert load_features(path, "key1").features is first.features
    with pytest.raises(DataError, match="missing"):
        load_features(path, "key1", from_disk=True)
    with pytest.raises(DataError, match="missing"):  # what the check found is remembered
        load_features(path, "key1")


def test_describe_checks_the_file_not_what_the_process_remembers(tmp_path: Path) -> None:
    """A worker that read a file keeps it in memory; if the file is gone or broken by the next
    run, that worker's describe job still writes it again (other workers read the file)."""
    path = tmp_path / "f.npz"
    save_features(path, "key", np.zeros(2), describe_ms=1.0)
    assert _has_features(path, "key")
    path.write_bytes(b"broken")
    assert not _has_features(path, "key")


def test_a_file_written_again_under_another_key_is_read_again(tmp_path: Path) -> None:
    path = tmp_path / "f.npz"
    save_features(path, "old inputs", np.zeros(2), describe_ms=1.0)
    assert load_features(path, "old inputs").describe_ms == 1.0
    with pytest.raises(DataError, match="other inputs"):
        load_features(path, "new inputs")
    save_features(path, "new inputs", np.ones(2), describe_ms=2.0)
    loaded = load_features(path, "new inputs")
    assert loaded.describe_ms == 2.0 and np.array_equal(loaded.features, np.ones(2))
    with pytest.raises(DataError, match="other inputs"):
        load_features(path, "old inputs")


def test_a_structure_that_is_not_an_object_is_refused_every_time(tmp_path: Path) -> None:
    path = tmp_path / "f.npz"
    np.savez(path, structure=np.frombuffer(b'["key"]', dtype=np.uint8))
    for _ in range(2):
        with pytest.raises(DataError, match="not a JSON object"):
            load_features(path, "key")


def test_a_planted_pickle_never_runs_and_a_corrupt_file_is_recomputed(
    tmp_path: Path, arena_manifest: Path
) -> None:
    marker = tmp_path / "executed"
    config = arena_config(tmp_path, arena_manifest, methods=[{"method": "warping"}])
    assert run_config(tmp_path, config).exit_code == 0
    run_dir = tmp_path / "run"
    # where homebench 0.1.0 read features: features/<hash of method and params>/<db>/<i>_<j>.pkl
    old = run_dir / "features" / stable_hash({"method": "warping", "params": {}})
    identity = next(next((run_dir / "features").iterdir()).iterdir()).name
    (old / identity).mkdir(parents=True, exist_ok=True)
    for i in range(4):
        for j in range(5):
            (old / identity / f"{i}_{j}.pkl").write_bytes(pickle.dumps(_Marker(marker)))
    for path in (run_dir / "features").rglob("*.npz"):
        path.with_suffix(".pkl").write_bytes(pickle.dumps(_Marker(marker)))
    feature_files = sorted((run_dir / "features").rglob("*.npz"))
    for path in feature_files[:1]:
        path.write_bytes(b"not a zip file")
    for job in (run_dir / "jobs").glob("*.json"):
        job.unlink()
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert "2 job(s) computed, 0 reused" in result.stdout
    assert not marker.exists()
    assert feature_files and feature_files[0].read_bytes()[:2] == b"PK"  # recomputed


def _bomb(path: Path, key: str, inflated: int) -> None:
    """A feature file of ``key`` whose one array, deflated to a few KB, inflates to
    ``inflated`` bytes (homebench writes its feature files uncompressed)."""
    structure = {"format": 1, "key": key, "describe_ms": 1.0, "features": {"array": 0}}
    text = np.frombuffer(json.dumps(structure).encode(), dtype=np.uint8)
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "|u1", "fortran_order": False, "shape": (inflated,)}
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        with archive.open("structure.npy", "w") as member:
            np.lib.format.write_array(member, text)
        with archive.open("a0.npy", "w", force_zip64=True) as member:
            member.write(header.getvalue())
            chunk = bytes(16 << 20)
            for start in range(0, inflated, len(chunk)):
                member.write(chunk[: inflated - start])


@pytest.mark.parametrize("key", ["k", "other key"])
def test_a_deflated_bomb_is_refused_before_it_inflates(tmp_path: Path, key: str) -> None:
    """The key and the members' sizes are checked in the zip directory: nothing inflates."""
    path = tmp_path / "bomb.npz"
    _bomb(path, key, 256 << 20)
    assert path.stat().st_size < 2 << 20
    tracemalloc.start()
    try:
        with pytest.raises(DataError, match="bomb.npz: unusable feature file"):
            load_features(path, "k")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 32 << 20


@pytest.mark.slow  # CI time: a worker's memory limit is tested in test_faults
def test_a_feature_file_that_exhausts_a_worker_is_recomputed(
    tmp_path: Path, arena_manifest: Path
) -> None:
    """A 3 MB file inflating to 1.5 GB failed every pair reading it (a worker of 1 GB), and a
    --retry-failed again: only --force helped. It is recomputed, and the run succeeds."""
    config = arena_config(
        tmp_path, arena_manifest, methods=[{"method": "warping"}], worker_memory_mb=1024
    )
    assert run_config(tmp_path, config).exit_code == 0
    run_dir = tmp_path / "run"
    victim = sorted((run_dir / "features").rglob("*.npz"))[0]
    with np.load(victim) as archive:
        key = json.loads(archive["structure"].tobytes())["key"]
    _bomb(victim, key, 3 << 29)
    for job in (run_dir / "jobs").glob("*.json"):
        job.unlink()
    result = run_config(tmp_path, config)
    assert result.exit_code == 0, result.output
    assert load_features(victim, key, from_disk=True).features is not None
