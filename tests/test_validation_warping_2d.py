"""Validation of 2D-warping (Möller 2009) on its paper's scene: 1-D warping's, every landmark at
one distance from the goal, now in two-dimensional images (a landmark's change of distance
also scales its column vertically).

The exact case, a textured cylinder round the goal ray-traced for parameters on the search
grid, is tests/test_warping_2d.py::test_search_recovers_the_parameters_of_an_equal_distance_
world. Here the **equal-distance arena** (rendered panoramas, tests/validation_scenes.py): the
goal at the centre of the round arena, its wall textured in azimuth and height, 24 places 0.3,
0.9 and 1.5 m away (rho 0.1-0.5) in 8 directions, each view as it is and turned by -37.5 deg
(10 psi steps). Measured: mean AE 1.8 deg (AHC 0.9995), at most 2.0 deg (the directions lie
between alpha steps of 3.75 deg); the turn exactly. Held to a mean of 3, a maximum of 5 and
half a psi step (1.875 deg). The same scene through the scale-plane scheme (``scheme=
"scale-planes"``: min-warping's stack, NSAD of edge-filtered columns, double and fine search):
mean AE 0.91 deg, at most 3.0 deg, the turn exactly; held to a mean of 2.5, a maximum of 6 and
one band column (1.25 deg), as min-warping on this scene.
"""

from __future__ import annotations

import numpy as np
import pytest
from validation_scenes import CENTRE, arena_errors, rich_texture, ring, use_wall

from homebench.methods.warping_2d.method import Warping2D


def test_equal_distance_arena(monkeypatch: pytest.MonkeyPatch):
    use_wall(monkeypatch, rich_texture)
    angle, rotation = arena_errors(Warping2D(), CENTRE, ring((0.3, 0.9, 1.5), 8), (0.0, -37.5))
    assert angle.mean() < 3.0 and angle.max() < 5.0
    assert np.all(rotation <= 1.875 + 1e-6)


def test_equal_distance_arena_on_the_scale_plane_stack(monkeypatch: pytest.MonkeyPatch):
    use_wall(monkeypatch, rich_texture)
    method = Warping2D(scheme="scale-planes")
    angle, rotation = arena_errors(method, CENTRE, ring((0.3, 0.9, 1.5), 8), (0.0, -37.5))
    assert angle.mean() < 2.5 and angle.max() < 6.0
    assert np.all(rotation <= 1.25 + 1e-6)
