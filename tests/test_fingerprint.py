"""Content fingerprints: equal for another processor's rounding, different for other content."""

from __future__ import annotations

import numpy as np
import pytest

from homebench.data.fingerprint import fingerprint, matches, parse
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import render_position

SPEC = WorldSpec(seed=1, grid={"shape": (3, 3)}, unfolded={"width": 180})


@pytest.fixture(scope="module")
def images() -> dict[str, np.ndarray]:
    return render_position(SPEC, 1, 1)


def test_the_fingerprint_is_exact_integer_arithmetic():
    image = np.zeros((24, 18), np.uint8)
    image[:, 9:] = 200  # the right half bright; 12 x 12 blocks, block 6 = columns 9-10
    mean, gradient, bits = parse(fingerprint(image))
    assert mean == 10000 and gradient == round(100 * 200 * 24 / (24 * 17))
    across = [0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]  # only block 5 (0) < block 6 (200)
    down = [0] * 12  # every column is constant
    assert bits == int("".join(map(str, across * 12 + down * 11)), 2)
    assert fingerprint(image) == fingerprint(image.copy())


@pytest.mark.parametrize("kind", ["raw", "unfolded"])
def test_rounding_differences_match(images, kind):
    """Pixels tipped by one grey level, as another processor's rounding does (here: 1 in
    500 lit pixels, far more than the handful seen between processors; a raw image's black
    frame is set to exact zeros, on every processor)."""
    image = images[kind]
    tipped = image.copy().ravel()
    rng = np.random.default_rng(0)
    lit = np.flatnonzero(tipped > 0)
    where = rng.choice(lit, lit.size // 500, replace=False)
    tipped[where] = np.clip(tipped[where].astype(int) + rng.choice([-1, 1], where.size), 0, 255)
    assert matches(fingerprint(image), fingerprint(tipped.reshape(image.shape)))


@pytest.mark.parametrize("kind", ["raw", "unfolded"])
def test_other_content_does_not_match(images, kind):
    """Another pose, seed or brightness. (Another noise draw of the same view matches: the
    fingerprint describes content, not a noise realisation.)"""
    image = images[kind]
    reference = fingerprint(image)
    others = {
        "neighbour": render_position(SPEC, 1, 2)[kind],
        "one level brighter": np.clip(image.astype(int) + 1, 0, 255).astype(np.uint8),
        "other seed": render_position(SPEC.model_copy(update={"seed": 2}), 1, 1)[kind],
    }
    if kind == "unfolded":
        others["turned"] = np.roll(image, 3, axis=1)
    for name, other in others.items():
        assert not matches(reference, fingerprint(other)), name
