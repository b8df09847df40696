"""The engine's ``compass: visual`` step on views in memory, for the methods' unit tests.

:func:`home_with_visual_compass` does what :mod:`homebench.evaluation.jobs` does for a pair of
a method entry with ``compass: visual`` (there the turned view is read from the database at the
combined rotation; here it is rolled): the visual compass's turn, the current view turned back
by it, the method on the aligned pair, the answer in the current robot frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from homebench.imaging.rotation import rotate_view
from homebench.methods.base import HomingEstimate, View
from homebench.methods.image_difference.visual_compass import compass_turn, in_current_frame


def home_with_visual_compass(method: Any, current: View, goal: View) -> HomingEstimate:
    """``method``'s estimate for (current, goal) views with the engine's visual compass."""
    turn = compass_turn(current, goal)
    aligned = rotate_view(current, -turn)
    estimate = method.home(method.describe(aligned), method.describe(goal))
    return in_current_frame(estimate, turn)


@dataclass(frozen=True)
class WithVisualCompass:
    """A method seen through the engine's visual compass: features are the views themselves,
    ``home`` is :func:`home_with_visual_compass` (for helpers that call describe and home)."""

    method: Any
    image_kind: ClassVar[str] = "unfolded"

    def describe(self, view: View) -> View:
        return view

    def home(self, current: View, goal: View) -> HomingEstimate:
        return home_with_visual_compass(self.method, current, goal)
