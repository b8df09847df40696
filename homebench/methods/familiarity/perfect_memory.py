"""Perfect memory route navigation (Baddeley, Graham, Husbands & Philippides 2012, PLoS Comput.
Biol. 8(1): e1002336): every training view stored, the heading by the best match.

Model: the memory is the list of the route's views, each taken facing the way the route runs.
The current view is rotated through every column shift and compared with every stored view by
an image difference over the whole view (``difference``): by default the mean absolute
difference of the grey levels, as the authors' group's public code compares views (Brains on
Board's ``PerfectMemory``, navbench); the root-mean-square difference (the rotational image
difference function, RIDF, of :func:`homebench.methods.image_difference.visual_compass.ridf`) on
request. The
unfamiliarity of a shift is its smallest difference over the stored views, and the agent heads
in the direction of the smallest of all (the protocol and conventions:
:mod:`homebench.methods.familiarity.route_memory`). The diagnostics name the best-matching view
(``view``,
its index in the training order: the route position the agent recognises).

Readings: the paper's comparison is an image difference over the whole down-sampled view; its
text, out of reach here, was not checked for which one, so the default follows the authors'
group's code (see the ``difference`` parameter). The two measures rank views differently: a squared
difference weighs a few large pixel differences (an object edge in the wrong place) more than
many small ones (a slightly brighter sky), so they can pick different stored views and
headings. The scan covers every column shift (a full turn; the paper's scan range is not
verified here). The view size is :class:`~homebench.methods.familiarity.route_memory.RouteMemory`'s.

Validation (tests/test_validation_route_memory.py), on the paper's kind of scene, a route
through clutter under an open sky (the generated ``outdoor`` style): an L-shaped route of 3 m,
a view every 0.1 m facing along it; 49 probes on the route and 0.25-1 m beside it, each at a
random heading. With the default (mean absolute difference): median heading error 0.7-1.6 deg
at every distance, 86-100 % of probes within 45 deg (the others take the route's other leg),
catchment the 1 m tested. With ``rms``: 0.7-1.9 deg, 86-93 %, catchment 1 m.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from homebench.methods.base import ImageKind
from homebench.methods.familiarity.route_memory import FloatArray, RouteMemory, rotations
from homebench.methods.image_difference.visual_compass import ridf
from homebench.methods.params import documented, param
from homebench.methods.registry import register

Difference = Literal["mad", "rms"]


def mean_absolute_ridf(current: FloatArray, views: FloatArray) -> FloatArray:
    """Mean absolute difference of ``roll(current, s, axis=-1)`` and each stored view, for every
    column shift ``s``: shape (m, n), for ``current`` (rows, n) and ``views`` (m, rows, n)."""
    rolled = rotations(np.asarray(current, dtype=np.float64))  # (n, rows * n)
    flat = np.asarray(views, dtype=np.float64).reshape(len(views), -1)
    if flat.shape[-1] != rolled.shape[-1]:
        raise ValueError(
            f"perfect-memory: views differ in shape, {np.shape(current)} and {np.shape(views)[1:]}"
        )
    out = np.empty((len(flat), rolled.shape[0]))
    scratch = np.empty_like(rolled)  # one view at a time, in place: memory stays (n, rows * n)
    for k, view in enumerate(flat):
        np.subtract(rolled, view, out=scratch)
        np.abs(scratch, out=scratch)
        out[k] = scratch.mean(axis=-1)
    return out


@register
@documented
@dataclass(frozen=True)
class PerfectMemory(RouteMemory):
    """Perfect memory (Baddeley et al. 2012): every route view stored; the heading is the
    rotation with the smallest image difference to the best-matching view."""

    name: ClassVar[str] = "perfect-memory"
    image_kind: ClassVar[ImageKind] = "unfolded"

    difference: Difference = param(
        "mad",
        "How a rotation of the current view is compared with a stored view: mad (the mean "
        "absolute difference of their grey levels) or rms (the root of the mean squared "
        "difference).",
        reading="Baddeley et al. (2012) compare whole down-sampled views by an image "
        "difference; their text was out of reach here, so the default follows the authors' "
        "group's public code: Brains on Board's perfect memory compares by the mean absolute "
        "difference (BoB robotics, include/navigation/perfect_memory_store_raw.h: "
        "PerfectMemoryStore::RawImage's default differencer is AbsDiff, 'the mean absolute "
        "difference between images', include/navigation/differencers.h), as does navbench "
        "(mean_absdiff, through BoB's Python bindings). rms is BoB's RMSDiff option and the "
        "root-mean-square pixel difference of Zeil, Hofmann & Chahl's (2003) image difference "
        "functions (homebench's visual-compass); homebench's perfect memory used it before. "
        "The two can pick different stored views and headings",
    )

    def learn(self, views: Sequence[FloatArray]) -> FloatArray:
        """The stored views, shape (m, rows, columns), in training order."""
        return np.stack([np.asarray(view, dtype=np.float64) for view in views])

    def differences(self, memory: FloatArray, current: FloatArray) -> FloatArray:
        """The image difference (``difference``) of every column shift of ``current`` to every
        stored view: shape (m, n)."""
        if self.difference == "mad":
            return mean_absolute_ridf(current, memory)
        return np.stack([ridf(current, view) for view in memory])

    def scan(self, memory: FloatArray, current: FloatArray) -> tuple[FloatArray, dict[str, Any]]:
        """Smallest difference over the stored views per shift (n,); ``view``: the best view's
        index."""
        profiles = self.differences(memory, current)  # (m, n)
        best = int(np.argmin(np.min(profiles, axis=1)))
        return np.min(profiles, axis=0), {"view": best}
