"""Snapshots stored along the outbound route for homing with a pairwise method.

A pairwise method homes from one view to another; a long route is followed back through views
stored on the way out (the snapshots), leg by leg. Two rules choose them, both options of
:class:`SnapshotRule`:

- ``spacing``: a snapshot at home and whenever the distance driven since the last one, as the
  odometry measures it (what the robot knows), reaches ``spacing_m`` metres. On a straight
  route of length L with steps s that divide the spacing, the snapshots are at 0, d, 2d, ...
  below L: ``floor(L / d) + 1`` of them, home included (one fewer when L is a multiple of d:
  the route's end is where homing starts, no target).
- ``similarity``: a snapshot at home and whenever the current view's distance to the last
  snapshot (:func:`view_distance`) reaches ``threshold`` grey levels. Reading: Zeil et al.
  (2003) found the image distance to grow smoothly with the distance from a snapshot over its
  catchment; storing a new snapshot before the distance passes a bound keeps each snapshot
  within the reach of the next one, wherever the scene changes fast (near walls) or slowly.

The route's last frame is never a snapshot: homing starts there.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from homebench.methods.image_difference.visual_compass import ridf

#: Distances within this of the spacing count as reaching it (float sums of steps).
SPACING_TOLERANCE = 1e-9


class SnapshotRule(BaseModel):
    """Where snapshots are stored: ``rule`` ``spacing`` (every ``spacing_m`` metres of
    odometry) or ``similarity`` (when the view distance to the last snapshot reaches
    ``threshold``, RMS grey levels); each rule reads its own field only."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    # spacing: every spacing_m of odometry; similarity: when the view has changed by threshold
    rule: Literal["spacing", "similarity"] = "spacing"
    spacing_m: float = Field(0.5, gt=0)  # spacing: metres driven (odometry) between snapshots
    # similarity: view distance to the last snapshot that stores a new one, RMS grey levels
    threshold: float = Field(12.0, gt=0)


def view_distance(image: ArrayLike, snapshot: ArrayLike) -> float:
    """Rotation-invariant distance of two unfolded panoramas of one shape (rows, columns):
    the smallest RMS grey-level difference over all column shifts (the minimum of the
    rotational image difference function,
    :func:`~homebench.methods.image_difference.visual_compass.ridf`), so
    it does not depend on the two headings."""
    return float(np.min(ridf(image, snapshot)))


def spacing_frames(odometry: ArrayLike, spacing: float) -> list[int]:
    """Frames (ascending, 0 first) of the snapshots every ``spacing`` metres of the odometry
    path ``odometry`` (n, >= 2) (x, y first); the last frame excluded."""
    xy = np.asarray(odometry, dtype=np.float64)[:, :2]
    steps = np.hypot(*np.diff(xy, axis=0).T)
    frames, since = [0], 0.0
    for k, step in enumerate(steps[:-1], start=1):
        since += float(step)
        if since >= spacing - SPACING_TOLERANCE:
            frames.append(k)
            since = 0.0
    return frames


def similarity_frames(images: Sequence[NDArray[np.uint8]], threshold: float) -> list[int]:
    """Frames (ascending, 0 first) of the snapshots chosen by ``threshold`` on the view distance
    to the last snapshot, among ``images`` (the panoramas of the frames before the route's
    end, one shape)."""
    frames = [0]
    for k in range(1, len(images)):
        if view_distance(images[k], images[frames[-1]]) >= threshold:
            frames.append(k)
    return frames
