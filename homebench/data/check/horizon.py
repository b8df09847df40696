"""Where the horizon is in a set of panoramas, from how points move between grid neighbours.

Under a pure translation towards azimuth ``m`` a scene point ahead (``cos(a - m) > 0``) moves
away from the horizon as the robot approaches it, whether it lies above or below, and a point
behind moves towards it; points at camera height (on the horizon) only move along it. So the
vertical image flow (rows, positive down) times ``sign(cos(a - m))`` has the sign of ``row -
horizon row``: its median over the columns within 60 deg of the motion's axis, row by row,
crosses zero at the horizon. The crossing is the split of the profile that leaves the least
positive mass above it and negative mass below, refined by linear interpolation.

Dense flow: OpenCV's DIS optical flow between the two panoramas (columns wrapped round).
Raw images are unfolded first (with their radial profile), so that one row is one elevation.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.data.check.pairs import GridIndex, Pair
from homebench.geometry import PanoramaGeometry, angle_diff

FloatArray = NDArray[np.float64]

#: Columns within this angle of the motion's axis (ahead or behind) enter the profile.
AXIS_HALF_ANGLE = np.radians(60.0)
#: Columns wrapped round each side before the flow, so that flow at the seam is not lost.
WRAP = 32


def vertical_flow(current: NDArray[np.uint8], goal: NDArray[np.uint8]) -> NDArray[np.float32]:
    """Vertical flow (rows, positive down) from ``current`` to ``goal`` (height, width)."""
    dis = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM)

    def wrapped(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
        return np.ascontiguousarray(np.concatenate([image[:, -WRAP:], image, image[:, :WRAP]], 1))

    flow = dis.calc(wrapped(current), wrapped(goal), None)
    return flow[:, WRAP:-WRAP, 1]


def flow_profile(
    panoramas: Mapping[GridIndex, NDArray[np.uint8]],
    geometry: PanoramaGeometry,
    pairs: Sequence[Pair],
    motions: FloatArray,
) -> FloatArray:
    """Per row, the median of vertical flow times ``sign(cos(azimuth - motion))`` over the
    columns near each pair's motion axis: shape (height,). ``motions`` (n_pairs,) are the
    azimuths (radians, ``geometry``'s frame) from each current position to its goal."""
    azimuths = geometry.column_to_azimuth(np.arange(geometry.width))
    signed = []
    for pair, motion in zip(pairs, motions, strict=True):
        cosine = np.cos(angle_diff(azimuths, motion))
        near = np.abs(cosine) >= np.cos(AXIS_HALF_ANGLE)
        flow = vertical_flow(panoramas[pair.current], panoramas[pair.goal])
        signed.append(flow[:, near] * np.sign(cosine[near]))
    return np.median(np.concatenate(signed, axis=1), axis=1).astype(np.float64)


def zero_crossing(profile: FloatArray) -> float:
    """Fractional row where ``profile`` (height,) goes from negative above to positive below:
    the split with the least positive mass above and negative mass below, then linear
    interpolation between the two rows around it."""
    above = np.concatenate([[0.0], np.cumsum(np.maximum(profile, 0.0))])
    below = np.concatenate([np.cumsum(np.maximum(-profile, 0.0)[::-1])[::-1], [0.0]])
    k = int(np.argmin(above + below))  # rows < k above, rows >= k below
    if 0 < k < profile.size and profile[k - 1] <= 0.0 <= profile[k]:
        low, high = profile[k - 1], profile[k]
        return k - 1 + (float(-low / (high - low)) if high > low else 0.5)
    return k - 0.5
