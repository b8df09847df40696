"""homebench.data.generate: layout, sums, reuse, determinism across jobs, nothing half-written.

Most tests use a fake renderer (seeded noise) so they run in milliseconds; one test renders a
tiny grid with the real renderer when it is installed.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from homebench.data import generate as generate_module
from homebench.data.catalog import ensure_generated, generate_variant, resolve
from homebench.data.generate import (
    Generation,
    generate,
    generate_many,
    generated_root,
    is_generated,
    manifest_for_spec,
)
from homebench.data.manifest import load_manifest
from homebench.data.synth.spec import GridSpec, RawImageSpec, UnfoldedImageSpec, WorldSpec
from homebench.errors import ConfigError, DataError
from homebench.fileio import read_grey


def small_spec(**fields: Any) -> WorldSpec:
    """A 3 x 4 grid with small images: generation in milliseconds."""
    raw = RawImageSpec(width=64, height=48, inner_radius=3.0, outer_radius=22.0)
    defaults = {"grid": GridSpec(shape=(3, 4)), "raw": raw, "unfolded": UnfoldedImageSpec(width=36)}
    return WorldSpec(**{**defaults, **fields})


class FakeRenderer:
    """Seeded noise per (seed, variant, i, j): deterministic, different at every position."""

    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, np.ndarray]:
        rng = np.random.default_rng([spec.seed, len(spec.variant), i, j])
        return {
            "raw": rng.integers(0, 256, (spec.raw.height, spec.raw.width), dtype=np.uint8),
            "unfolded": rng.integers(
                0, 256, (spec.unfolded.height, spec.unfolded.width), dtype=np.uint8
            ),
        }

    def ground_truth(self, spec: WorldSpec) -> dict[str, Any]:
        return {"room": [spec.room_extent.width, spec.room_extent.depth], "objects": []}


class FailingRenderer(FakeRenderer):
    """Fails at one grid position, as an interrupted or crashing generation would."""

    def __init__(self, fail_at: tuple[int, int]):
        self.fail_at = fail_at

    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, np.ndarray]:
        if (i, j) == self.fail_at:
            raise RuntimeError(f"renderer crashed at {self.fail_at}")
        return super().render_position(spec, i, j)


class WrongSizeRenderer(FakeRenderer):
    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, np.ndarray]:
        images = super().render_position(spec, i, j)
        return {**images, "unfolded": images["unfolded"][:-1]}


def _tree(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def test_generate_writes_layout_manifest_sums_and_ground_truth(tmp_path: Path) -> None:
    spec = small_spec(seed=3, variant="chairs")
    calls = []
    out = generate(
        spec,
        tmp_path / "db",
        1,
        "tiny",
        renderer=FakeRenderer(),
        progress=lambda *a: calls.append(a),
    )
    assert out == tmp_path / "db"
    files = _tree(out)
    expected = {f"{k}/{i}_{j}.png" for k in ("raw", "unfolded") for i in range(3) for j in range(4)}
    assert set(files) == expected | {"manifest.yaml", "ground_truth.json"}
    manifest = load_manifest(out / "manifest.yaml")
    assert manifest.name == "tiny"
    assert manifest.generator.spec == spec and manifest.generator.key == spec.key()
    for kind in ("raw", "unfolded"):
        sums = manifest.section(kind).files
        assert len(sums) == 12
        for name, digest in sums.items():
            assert hashlib.sha256(files[f"{kind}/{name}"]).hexdigest() == digest
    image = FakeRenderer().render_position(spec, 2, 1)["raw"]
    np.testing.assert_array_equal(read_grey(out / "raw" / "2_1.png"), image)
    truth = json.loads(files["ground_truth.json"])
    assert truth["spec_key"] == spec.key()
    assert truth["world"] == FakeRenderer().ground_truth(spec)
    pose = spec.pose(2, 3)
    assert truth["poses"]["2_3"] == pytest.approx({"x": pose.x, "y": pose.y, "heading": 0.0})
    assert calls[-1] == (12, 12)


def test_a_finished_folder_is_reused_not_regenerated(tmp_path: Path) -> None:
    spec = small_spec()
    out = generate(spec, tmp_path / "db", 1, "tiny", renderer=FakeRenderer())
    before = _tree(out)
    again = generate(spec, tmp_path / "db", 1, "tiny", renderer=FailingRenderer((0, 0)))
    assert again == out
    assert _tree(out) == before


def test_an_unrelated_existing_folder_is_never_overwritten(tmp_path: Path) -> None:
    (tmp_path / "db").mkdir()
    (tmp_path / "db" / "notes.txt").write_text("mine")
    with pytest.raises(DataError, match="not a finished generation"):
        generate(small_spec(), tmp_path / "db", 1, "tiny", renderer=FakeRenderer())
    other = generate(small_spec(seed=1), tmp_path / "other", 1, "tiny", renderer=FakeRenderer())
    with pytest.raises(DataError, match="not a finished generation"):
        generate(small_spec(seed=2), other, 1, "tiny", renderer=FakeRenderer())
    assert (tmp_path / "db" / "notes.txt").read_text() == "mine"
    (tmp_path / "empty").mkdir()
    empty = generate(small_spec(), tmp_path / "empty", 1, "tiny", renderer=FakeRenderer())
    assert is_generated(empty, small_spec())


def test_identical_bytes_with_one_and_two_jobs(tmp_path: Path) -> None:
    spec = small_spec(seed=5)
    one = generate(spec, tmp_path / "one", 1, "tiny", renderer=FakeRenderer())
    two = generate(spec, tmp_path / "two", 2, "tiny", renderer=FakeRenderer())
    assert _tree(one) == _tree(two)


def test_on_start_is_called_before_rendering_and_only_when_a_world_is_pending(
    tmp_path: Path,
) -> None:
    """(A run starts its workers' set-up there, while the worlds render.)"""
    together = [Generation(small_spec(seed=s), tmp_path / f"db-{s}", "tiny") for s in (5, 6)]
    rendered: list[tuple[int, int]] = []

    class Counting(FakeRenderer):
        def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, np.ndarray]:
            rendered.append((i, j))
            return super().render_position(spec, i, j)

    seen: list[int] = []
    generate_many(together, 1, renderer=Counting(), on_start=lambda: seen.append(len(rendered)))
    assert seen == [0]  # once, before the first position
    generate_many(together, 1, renderer=FailingRenderer((0, 0)), on_start=lambda: seen.append(1))
    assert seen == [0]  # both generated: nothing to start


@pytest.mark.parametrize("jobs", [1, 2])
def test_nothing_half_written_when_generation_fails(tmp_path: Path, jobs: int) -> None:
    with pytest.raises(RuntimeError, match="renderer crashed"):
        generate(small_spec(), tmp_path / "db", jobs, "tiny", renderer=FailingRenderer((1, 2)))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("jobs", [1, 2])
def test_worlds_generated_together_are_the_worlds_generated_alone(
    tmp_path: Path, jobs: int
) -> None:
    """One pass over several worlds (ground truth computed in the pool's workers) writes the
    same bytes as one generation per world; a world already generated is left as it is."""
    specs = [small_spec(seed=5), small_spec(seed=5, variant="day"), small_spec(seed=6)]
    alone = [generate(s, tmp_path / f"alone-{k}", 1, "tiny", renderer=FakeRenderer())
             for k, s in enumerate(specs)]  # fmt: skip
    done = generate(specs[0], tmp_path / "together-0", 1, "tiny", renderer=FakeRenderer())
    kept = _tree(done)
    together = [Generation(s, tmp_path / f"together-{k}", "tiny") for k, s in enumerate(specs)]
    calls: list[tuple[int, int]] = []
    folders = generate_many(together, jobs, renderer=FakeRenderer(),
                            progress=lambda d, n: calls.append((d, n)))  # fmt: skip
    assert folders == [g.folder for g in together]
    assert [_tree(f) for f in folders] == [_tree(f) for f in alone]
    assert _tree(done) == kept
    assert calls[-1] == (24, 24)  # the two worlds still to generate, 12 positions each


@pytest.mark.parametrize("jobs", [1, 2])
def test_one_world_failing_leaves_none_of_the_worlds_half_written(
    tmp_path: Path, jobs: int
) -> None:
    together = [Generation(small_spec(seed=k), tmp_path / f"db-{k}", "tiny") for k in range(3)]
    with pytest.raises(RuntimeError, match="renderer crashed"):
        generate_many(together, jobs, renderer=FailingRenderer((2, 3)))
    assert list(tmp_path.iterdir()) == []


class RacingRenderer(FakeRenderer):
    """Another process finishes ``spec`` in ``folder`` while this one renders it."""

    def __init__(self, spec: WorldSpec, folder: Path):
        self.spec, self.folder = spec, folder

    def render_position(self, spec: WorldSpec, i: int, j: int) -> dict[str, np.ndarray]:
        if spec == self.spec and not self.folder.exists():
            generate(spec, self.folder, 1, "tiny", renderer=FakeRenderer())
        return super().render_position(spec, i, j)


def test_a_world_another_process_finishes_first_is_taken_and_the_others_still_move_in(
    tmp_path: Path,
) -> None:
    together = [Generation(small_spec(seed=k), tmp_path / f"db-{k}", "tiny") for k in range(3)]
    racing = RacingRenderer(together[1].spec, together[1].folder)
    assert generate_many(together, 1, renderer=racing) == [g.folder for g in together]
    assert all(is_generated(g.folder, g.spec) for g in together)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["db-0", "db-1", "db-2"]


def test_two_worlds_cannot_share_a_folder(tmp_path: Path) -> None:
    together = [Generation(small_spec(seed=k), tmp_path / "db", "tiny") for k in range(2)]
    with pytest.raises(DataError, match="two different worlds"):
        generate_many(together, 1, renderer=FakeRenderer())
    assert list(tmp_path.iterdir()) == []
    same = [Generation(small_spec(), tmp_path / "db", "tiny")] * 2
    assert generate_many(same, 1, renderer=FakeRenderer()) == [tmp_path / "db"] * 2


def test_a_renderer_returning_the_wrong_size_is_a_data_error(tmp_path: Path) -> None:
    with pytest.raises(DataError, match=r"unfolded image of shape \(9, 36\)"):
        generate(small_spec(), tmp_path / "db", 1, "tiny", renderer=WrongSizeRenderer())
    assert list(tmp_path.iterdir()) == []


def test_default_folder_is_in_the_data_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOMEBENCH_DATA", str(tmp_path / "data"))
    spec = small_spec()
    out = generate(spec, None, 1, "tiny", renderer=FakeRenderer())
    assert out == tmp_path / "data" / "synth" / f"tiny-{spec.key()}" == generated_root("tiny", spec)
    assert is_generated(out, spec)
    assert not is_generated(out, small_spec(seed=9))


@pytest.fixture
def tiny_catalog(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> WorldSpec:
    """A known generated set "tiny-arboreal" (manifest in HOMEBENCH_MANIFESTS), fake renderer."""
    monkeypatch.setenv("HOMEBENCH_DATA", str(tmp_path / "data"))
    manifests = tmp_path / "manifests"
    manifests.mkdir()
    spec = small_spec(variant="arboreal", seed=4)
    (manifests / "tiny.yaml").write_text(manifest_for_spec(spec, "tiny-arboreal").to_yaml())
    monkeypatch.setenv("HOMEBENCH_MANIFESTS", str(manifests))
    fake = FakeRenderer()
    monkeypatch.setattr(generate_module.SynthRenderer, "render_position", fake.render_position)
    monkeypatch.setattr(generate_module.SynthRenderer, "ground_truth", fake.ground_truth)
    return spec


def test_ensure_generated_through_the_catalog(tiny_catalog: WorldSpec) -> None:
    with pytest.raises(DataError, match="not generated .*homebench data generate tiny-arboreal"):
        resolve("tiny-arboreal")
    db = ensure_generated("tiny-arboreal")
    assert db.root == generated_root("tiny-arboreal", tiny_catalog)
    assert db.manifest.section("raw").files  # the generated manifest, with sums
    assert resolve("tiny-arboreal").root == db.root
    assert resolve(db.root).root == db.root  # the folder itself names the database
    assert db.ground_truth()["world"] == FakeRenderer().ground_truth(tiny_catalog)
    with pytest.raises(DataError, match="real set"):
        ensure_generated("bielefeld-day")


def test_generate_variant_keeps_the_world_and_swaps_the_variant(
    tiny_catalog: WorldSpec, tmp_path: Path
) -> None:
    db = generate_variant("tiny-arboreal", "day")
    spec = db.manifest.generator.spec
    assert db.name == "tiny-day" and spec.variant == "day"
    assert spec.model_dump(exclude={"variant"}) == tiny_catalog.model_dump(exclude={"variant"})
    assert db.root == generated_root("tiny-day", spec)
    assert generate_variant("tiny-arboreal", "winlit", tmp_path / "w").root == tmp_path / "w"
    with pytest.raises(ConfigError, match="unknown variant 'dusk'"):
        generate_variant("tiny-arboreal", "dusk")


@pytest.mark.skipif(
    importlib.util.find_spec("homebench.data.synth.world") is None, reason="no renderer yet"
)
def test_real_renderer_on_a_tiny_grid(tmp_path: Path) -> None:
    spec = WorldSpec(grid=GridSpec(shape=(2, 2)))
    out = generate(spec, tmp_path / "db", 1, "real-tiny")
    manifest = load_manifest(out / "manifest.yaml")
    assert len(manifest.section("unfolded").files) == 4
    assert read_grey(out / "raw" / "1_1.png").shape == (spec.raw.height, spec.raw.width)
    assert read_grey(out / "unfolded" / "0_1.png").shape == (
        spec.unfolded.height,
        spec.unfolded.width,
    )
    assert "world" in json.loads((out / "ground_truth.json").read_text())
