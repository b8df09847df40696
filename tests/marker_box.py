"""A generated world plus a checkered box whose faces each show an X corner at their centre:
the ground truth of the ray caster's bearing tests (test_synth_world.py, test_synth_tilt.py)."""

from __future__ import annotations

import numpy as np

from homebench.data.synth import textures as tx
from homebench.data.synth.scene import Box, texture_shape
from homebench.data.synth.spec import WorldSpec
from homebench.data.synth.world import World, build_world

#: The box: centre (m), angle (rad), side (m), bottom and top (m).
MARKER_CENTRE, MARKER_ANGLE, MARKER_SIZE, MARKER_Z = (3.0, 4.2), 0.3, 0.4, (0.55, 1.25)


def with_marker(spec: WorldSpec, scene_spec: WorldSpec | None = None) -> World:
    """The world of ``spec`` whose scene is that of ``scene_spec`` (default ``spec``) plus the
    checkered box."""
    base = build_world(scene_spec or spec).scene
    side = tx.checker(texture_shape(4 * MARKER_SIZE, MARKER_Z[1] - MARKER_Z[0]), (2, 8))
    marker = Box(
        "marker",
        *MARKER_Z,
        side,
        tx.blank((8, 8), 0.5),
        centre=MARKER_CENTRE,
        size=(MARKER_SIZE, MARKER_SIZE),
        angle=MARKER_ANGLE,
    )
    return World(spec, base.with_objects([marker]), len(base.objects))


def face_centres() -> list[tuple[np.ndarray, np.ndarray]]:
    """(3-D face centre (3,), outward horizontal normal (2,)) of the box's four faces."""
    ca, sa = np.cos(MARKER_ANGLE), np.sin(MARKER_ANGLE)
    out = []
    for nx, ny in ((0, -1), (1, 0), (0, 1), (-1, 0)):
        n = np.array([nx * ca - ny * sa, nx * sa + ny * ca])
        c = np.array(MARKER_CENTRE) + MARKER_SIZE / 2 * n
        out.append((np.array([c[0], c[1], sum(MARKER_Z) / 2]), n))
    return out
