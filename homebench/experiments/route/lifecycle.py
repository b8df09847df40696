"""Feature life-cycles along a route and the intermediate positions of homing (seed 000, 2.3).

While the robot drives its outbound route, every tracked corner lives from the frame it is
detected in to the last frame it is tracked in (Fig. 3); a lost track never comes back (new
corners get new ids), so a life-cycle is one interval of frames. Two frames ``a <= b`` share
the features whose life-cycle covers both.

Homing goes backwards: from the last frame, the first target is the earliest frame that still
shares at least ``min_shared`` features with it (the paper's K: 3 in theory, 80 in its run);
from there the next target is chosen the same way, until the home frame 0 is reached.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from homebench.errors import HomebenchError
from homebench.methods.klt_sector.tracking import Tracks

IntArray = NDArray[np.int64]
F32Array = NDArray[np.float32]


class TargetSelectionError(HomebenchError):
    """No earlier frame shares enough features with a frame of the route."""


@dataclass
class FeatureLog:
    """The features alive in each frame of a route, in the order the frames were recorded.

    ``frames[k]`` = (ids (n,) int64, positions (n, 2) float32 (column, row) pixels).
    """

    frames: list[tuple[IntArray, F32Array]] = field(default_factory=list)

    def record(self, tracks: Tracks) -> None:
        """Append a frame: the alive rows of ``tracks``."""
        alive = tracks.survivors()
        self.frames.append((alive.ids.copy(), alive.positions.copy()))

    def __len__(self) -> int:
        return len(self.frames)

    def lifecycles(self) -> IntArray:
        """Rows (id, first frame, last frame) of every feature seen, by id; shape (f, 3)."""
        first: dict[int, int] = {}
        last: dict[int, int] = {}
        for k, (ids, _) in enumerate(self.frames):
            for i in ids.tolist():
                first.setdefault(i, k)
                last[i] = k
        rows = [(i, first[i], last[i]) for i in sorted(first)]
        return np.asarray(rows, dtype=np.int64).reshape(-1, 3)

    def positions(self, frame: int, ids: IntArray) -> F32Array:
        """Positions (len(ids), 2) in ``frame`` of features alive there (KeyError otherwise)."""
        frame_ids, frame_positions = self.frames[frame]
        row = {i: k for k, i in enumerate(frame_ids.tolist())}
        return frame_positions[[row[i] for i in np.asarray(ids).tolist()]].reshape(-1, 2)


def shared_ids(lifecycles: IntArray, a: int, b: int) -> IntArray:
    """Ids of the features alive in every frame from ``a`` to ``b`` (a <= b); shape (m,)."""
    covers = (lifecycles[:, 1] <= a) & (lifecycles[:, 2] >= b)
    return lifecycles[covers, 0]


def select_targets(lifecycles: IntArray, end: int, min_shared: int) -> list[int]:
    """Frames to home through from ``end`` back to 0, in the order visited (0 last).

    Each target is the earliest frame sharing at least ``min_shared`` features with the
    previous one (``end`` first). Raises :class:`TargetSelectionError` when not even the frame
    just before shares that many. ``end == 0`` gives no targets.
    """
    if min_shared < 1:
        raise ValueError(f"min_shared must be >= 1, got {min_shared}")
    first, last = lifecycles[:, 1], lifecycles[:, 2]
    targets: list[int] = []
    current = end
    while current > 0:
        alive_now = (first <= current) & (last >= current)
        born = first[alive_now]  # features alive at `current`; each covers [born, current]
        # Frame j shares with `current` the features born at or before j: a count that grows
        # with j. The earliest j that reaches min_shared is the min_shared-th smallest birth.
        if born.size < min_shared or np.sort(born)[min_shared - 1] >= current:
            shared = int(np.count_nonzero(born <= current - 1))
            raise TargetSelectionError(
                f"frames {current - 1} and {current} of the route share {shared} features, "
                f"fewer than min_shared = {min_shared}"
            )
        current = int(np.sort(born)[min_shared - 1])
        targets.append(current)
    return targets
