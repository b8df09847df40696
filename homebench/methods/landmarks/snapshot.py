"""The snapshot model of Cartwright and Collett (1983, J. Comp. Physiol. 151, 521-543).

Model: the goal view (the snapshot) and the current view are horizons of dark sectors
(landmarks) and bright sectors (gaps between them). Every snapshot sector is paired with the
current sector of the same kind whose bearing is closest to its own. Each pair contributes two
unit vectors at the current place: a **tangential** one, perpendicular to the current sector's
bearing, pointing the way that turns that bearing towards the snapshot bearing (moving to the
right of a sector turns it to the left, and vice versa), and a **radial** one along the current
sector's bearing, towards the sector when it looks smaller than in the snapshot (approach to
enlarge it) and away from it when it looks larger. The home vector is their (weighted) sum.

Here bearings are in the current robot frame, aligned with the snapshot's as the bee's compass
aligns them: a grid database's common heading is that alignment; a config entry's ``compass:
visual`` (engine level, any method) turns the current view back by the visual compass's heading
change first. The segmentation is ALV's (:mod:`homebench.methods.landmarks.horizon`: Otsu's
threshold by default). A pair whose bearings (sizes) agree exactly adds no tangential (radial)
vector.

Validation scene (tests/test_validation_snapshot.py): ALV's, the paper's black cylinders on a
bright, unevenly lit wall (style ``arena``): AHC 0.991 against 0.993 on the world's
ground-truth landmarks, no pair off by more than 45 deg. The mean threshold's extra sectors
(the dim wall) cost less than in ALV: AHC 0.981, 1.2 % of the pairs beyond 45 deg.

No direction without evidence: no pair of sectors (a flat horizon) gives
:meth:`HomingEstimate.none`; a zero sum (identical views) gives ``angle=None``.

Paper look-up (issue 14): the relative weight of the tangential and radial vectors is not in
reach here. The searched public pages hold the abstracts of Cartwright and Collett's later
papers ("Landmark maps for honeybees", 1987: the bee "moves so as to reduce the discrepancy"
between snapshot and image) but not the 1983 model's equations. Chosen as equal unit weights
(options ``tangential_weight``, ``radial_weight``), to be checked against the paper.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import angle_diff
from homebench.methods.base import HomingEstimate, ImageKind
from homebench.methods.landmarks.horizon import LandmarkViews, Sectors, vector_direction
from homebench.methods.params import documented, param
from homebench.methods.registry import register

FloatArray = NDArray[np.float64]

#: Bearing difference (radians) below which a pair counts as aligned (rounding), so identical
#: views give no tangential vectors.
BEARING_TOLERANCE = 1e-9


def pair_sectors(snapshot: Sectors, current: Sectors) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Indices (snapshot_index, current_index), shape (p,) each: every snapshot sector with the
    current sector of the same kind nearest in bearing (the first of ties); snapshot sectors
    with no current sector of their kind are left out."""
    gap = np.abs(angle_diff(snapshot.centres[:, None], current.centres[None, :]))
    gap[snapshot.dark[:, None] != current.dark[None, :]] = np.inf
    paired = np.isfinite(gap).any(axis=1)
    snap = np.flatnonzero(paired)
    if snap.size == 0:
        return snap, np.zeros(0, dtype=np.intp)
    return snap, np.argmin(gap[snap], axis=1).astype(np.intp)


def snapshot_vectors(snapshot: Sectors, current: Sectors) -> tuple[FloatArray, FloatArray, int]:
    """Sums (2,) of the tangential and of the radial unit vectors of all sector pairs, in the
    current robot frame (x = heading), and the number of pairs."""
    snap, now = pair_sectors(snapshot, current)
    bearing = current.centres[now]
    mismatch = angle_diff(snapshot.centres[snap], bearing)
    turn = np.where(np.abs(mismatch) > BEARING_TOLERANCE, np.sign(mismatch), 0.0)  # +1: turn ccw
    grow = np.sign(snapshot.widths[snap] - current.widths[now])  # +1: sector must look larger
    tangential = turn * np.stack([np.sin(bearing), -np.cos(bearing)])  # bearing - turn * 90 deg
    radial = grow * np.stack([np.cos(bearing), np.sin(bearing)])
    return tangential.sum(axis=1), radial.sum(axis=1), int(snap.size)


@register
@documented
@dataclass(frozen=True)
class SnapshotModel(LandmarkViews):
    """Snapshot model (Cartwright and Collett 1983): summed tangential and radial unit vectors of
    paired horizon sectors."""

    name: ClassVar[str] = "snapshot"
    image_kind: ClassVar[ImageKind] = "unfolded"

    tangential_weight: float = param(
        1.0,
        "Weight of the summed tangential (bearing) unit vectors in the home vector.",
        reading="unit vectors of both kinds summed alike, as the model is usually stated; the "
        "paper's own relative weighting could not be consulted, and later robot versions weigh "
        "the two kinds differently, which these weights allow",
    )
    radial_weight: float = param(
        1.0,
        "Weight of the summed radial (apparent size) unit vectors in the home vector.",
        reading="see tangential_weight",
    )

    def __post_init__(self) -> None:
        self.check_landmark_params()
        if self.tangential_weight < 0 or self.radial_weight < 0:
            raise ConfigError("snapshot: the weights must not be negative")
        if self.tangential_weight + self.radial_weight == 0:
            raise ConfigError("snapshot: at least one weight must be positive")

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """Home direction: the angle of the weighted sum of the pairs' unit vectors; the
        features are horizon signals (n,)."""
        tangential, radial, pairs = snapshot_vectors(self.sectors(goal), self.sectors(current))
        if pairs == 0:
            return HomingEstimate.none(reason="no sector pairs")
        vector = self.tangential_weight * tangential + self.radial_weight * radial
        return HomingEstimate(
            angle=vector_direction(vector),
            n_landmarks=pairs,
            score=float(np.hypot(*vector)),
            diagnostics={"tangential": tangential.tolist(), "radial": radial.tolist()},
        )
