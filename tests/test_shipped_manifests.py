"""The shipped manifests: valid, and the generated sets' sums reproduce bit for bit."""

from __future__ import annotations

import hashlib

import pytest

from homebench.data.catalog import known_manifests
from homebench.data.synth.world import render_position
from homebench.fileio import encode_png

SYNTH = [f"synth-{v}" for v in ("original", "arboreal", "chairs", "day", "twilight", "winlit")]
BIELEFELD = [f"bielefeld-{v}" for v in ("original", "arboreal", "chairs", "day")]


def test_every_shipped_set_is_known_with_its_layout() -> None:
    known = known_manifests()
    for name in SYNTH + BIELEFELD:
        manifest = known[name].manifest
        assert manifest.to_grid().shape == (10, 17)
        assert manifest.to_grid().spacing == pytest.approx(0.30)
    for name in BIELEFELD:
        assert known[name].manifest.section("raw").size == (752, 564)


@pytest.mark.parametrize("name", SYNTH)
def test_generated_sums_reproduce(name: str) -> None:
    """Rendering a few positions gives exactly the files whose sums the manifest ships."""
    manifest = known_manifests()[name].manifest
    assert manifest.generator is not None
    spec = manifest.generator.spec
    assert manifest.generator.key == spec.key(), "manifest sums are stale: regenerate them"
    for i, j in [(0, 0), (5, 9)]:
        images = render_position(spec, i, j)
        for kind in ("raw", "unfolded"):
            expected = manifest.section(kind).files[f"{i}_{j}.png"]
            assert hashlib.sha256(encode_png(images[kind])).hexdigest() == expected, (kind, i, j)
