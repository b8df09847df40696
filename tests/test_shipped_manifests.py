"""The shipped manifests: valid, and the generated sets' sums reproduce bit for bit."""

from __future__ import annotations

import hashlib

import pytest

from homebench.data.catalog import known_manifests
from homebench.data.fingerprint import fingerprint, matches
from homebench.data.synth.world import render_position
from homebench.fileio import encode_png

VARIANTS = ("original", "arboreal", "chairs", "day", "twilight", "winlit")
SYNTH = [f"synth-{v}" for v in VARIANTS] + [
    f"synth-{style}-{v}" for style in ("lab", "corridor", "outdoor") for v in VARIANTS
]
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
    """Rendering a few positions gives the files whose sums the manifest ships: bit for bit
    on the reference machine, within the content-fingerprint tolerance on processors that
    round differently (:mod:`homebench.data.fingerprint`)."""
    manifest = known_manifests()[name].manifest
    assert manifest.generator is not None
    spec = manifest.generator.spec
    assert manifest.generator.key == spec.key(), "manifest sums are stale: regenerate them"
    for i, j in [(0, 0), (5, 9)]:
        images = render_position(spec, i, j)
        for kind in ("raw", "unfolded"):
            section, name = manifest.section(kind), f"{i}_{j}.png"
            if hashlib.sha256(encode_png(images[kind])).hexdigest() != section.files[name]:
                assert matches(fingerprint(images[kind]), section.fingerprints[name]), (kind, i, j)
