"""Perfect memory route navigation (Baddeley, Graham, Husbands & Philippides 2012, PLoS Comput.
Biol. 8(1): e1002336): every training view stored, the heading by the best match.

Model: the memory is the list of the route's views, each taken facing the way the route runs.
The current view is rotated through every column shift and compared with every stored view by
the root-mean-square pixel difference (the rotational image difference function, RIDF, of
:func:`homebench.methods.visual_compass.ridf`); the unfamiliarity of a shift is its smallest
difference over the stored views, and the agent heads in the direction of the smallest of all
(the protocol and conventions: :mod:`homebench.methods.familiarity`). The diagnostics name the
best-matching view (``view``, its index in the training order: the route position the agent
recognises).

Readings: the paper's comparison is an image difference over the whole down-sampled view; RMS
and the sum of squared differences have the same minimum (a monotone map of one another for
views of one size), so the choice changes no heading, only the ``score``. The scan covers every
column shift (a full turn; the paper's scan range is not verified here). The view size is
:class:`~homebench.methods.familiarity.RouteMemory`'s.

Validation (tests/test_validation_route_memory.py), on the paper's kind of scene, a route
through clutter under an open sky (the generated ``outdoor`` style): an L-shaped route of 3 m,
a view every 0.1 m facing along it; 49 probes on the route and 0.25-1 m beside it, each at a
random heading. Median heading error 0.7-1.9 deg at every distance, 86-93 % of probes within
45 deg (the others take the route's other leg), catchment the 1 m tested.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from homebench.methods.base import ImageKind
from homebench.methods.familiarity import FloatArray, RouteMemory
from homebench.methods.params import documented
from homebench.methods.registry import register
from homebench.methods.visual_compass import ridf


@register
@documented
@dataclass(frozen=True)
class PerfectMemory(RouteMemory):
    """Perfect memory (Baddeley et al. 2012): every route view stored; the heading is the
    rotation with the smallest image difference to the best-matching view."""

    name: ClassVar[str] = "perfect-memory"
    image_kind: ClassVar[ImageKind] = "unfolded"

    def learn(self, views: Sequence[FloatArray]) -> FloatArray:
        """The stored views, shape (m, rows, columns), in training order."""
        return np.stack([np.asarray(view, dtype=np.float64) for view in views])

    def scan(self, memory: FloatArray, current: FloatArray) -> tuple[FloatArray, dict[str, Any]]:
        """Smallest RIDF over the stored views per shift (n,); ``view``: the best view's
        index."""
        profiles = np.stack([ridf(current, view) for view in memory])  # (m, n)
        best = int(np.argmin(np.min(profiles, axis=1)))
        return np.min(profiles, axis=0), {"view": best}
