"""Azimuth direction and offset of a database's images, from homing between grid neighbours.

The grid gives every neighbour pair's true home direction in the manifest's robot frame
(``home_direction`` of the two positions and the current image's heading; each reading of the
grid's labels its own: :mod:`.readings`). A homing method
run on views that carry an azimuth model answers in that model's frame, so the residuals
``truth - estimate`` are, up to the method's errors:

- one constant, the **azimuth offset** (what must be added to every azimuth of the model),
  when the model's direction is the images' direction;
- ``2 * truth - constant`` when it is the mirror image: pairs along x and pairs along y then
  disagree by 180 deg, and no offset fits (mean AE about 90 deg).

A method's errors depend on the direction of the move in a given place (min-warping's
residuals in the generated outdoor square: -15 deg along +x, 0 along -y), so the offset is
fitted per way (+x, -x, +y, -y: each the circular median of its residuals, refined to the
circular mean of those within 20 deg of it), the ways are averaged with equal weights, and
their scatter gives the offset's standard error.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from homebench.data.check.pairs import GridIndex, Pair
from homebench.geometry import angle_diff, circular_mean
from homebench.views import View

FloatArray = NDArray[np.float64]

#: Residuals within this many radians of a way's circular median refine its offset.
INLIER_RADIUS = np.radians(20.0)


@dataclass(frozen=True)
class AzimuthFit:
    """Neighbour homing under one azimuth model; angles in radians.

    ``offset``: the azimuth to add to the model's (the images' azimuths are the model's plus
    it), with its standard error ``offset_se`` over the ways; ``mean_ae``: mean AE with the
    offset removed, ``mean_ae_as_is`` without (what a run would see), each way weighing
    alike; ``n_homed`` of ``n_pairs`` pairs had an estimate.
    """

    offset: float
    offset_se: float
    mean_ae: float
    mean_ae_as_is: float
    n_homed: int
    n_pairs: int


def home_estimates(
    method: Any, views: Mapping[GridIndex, View], pairs: Sequence[Pair]
) -> FloatArray:
    """``method``'s home direction of each pair, shape (n_pairs,), radians; NaN where the
    method gives none. Each view is described once."""
    features = {ij: method.describe(views[ij]) for p in pairs for ij in (p.current, p.goal)}
    angles = [method.home(features[p.current], features[p.goal]).angle for p in pairs]
    return np.array([np.nan if a is None else a for a in angles], dtype=np.float64)


def robust_offset(residuals: FloatArray) -> float:
    """Circular median of ``residuals`` (n,), refined to the circular mean of those within
    :data:`INLIER_RADIUS` of it; radians."""
    spread = np.abs(angle_diff(residuals[:, None], residuals[None, :])).sum(axis=1)
    median = residuals[np.argmin(spread)]
    return circular_mean(residuals[np.abs(angle_diff(residuals, median)) <= INLIER_RADIUS])


def fit_offset(truths: FloatArray, estimates: FloatArray, pairs: Sequence[Pair]) -> AzimuthFit:
    """The azimuth offset that best explains ``truths - estimates`` (shapes (n_pairs,),
    radians; NaN estimates are pairs without one): see the module docstring."""
    homed = np.isfinite(estimates)
    residuals = angle_diff(truths[homed], estimates[homed])
    ways = np.array([p.way for p in pairs])[homed]
    groups = [residuals[ways == way] for way in sorted(set(ways))]
    if not groups:
        return AzimuthFit(np.nan, np.nan, np.nan, np.nan, 0, len(pairs))
    offsets = np.array([robust_offset(g) for g in groups])
    offset = circular_mean(offsets)
    scatter = angle_diff(offsets, offset)
    se = float(np.sqrt(np.sum(scatter**2) / max(len(groups) - 1, 1) / len(groups)))
    return AzimuthFit(
        offset, se, _mean_ae(groups, offset), _mean_ae(groups, 0.0), int(homed.sum()), len(pairs)
    )


def _mean_ae(groups: list[FloatArray], offset: float) -> float:
    """Mean AE (radians) of residual ``groups`` once ``offset`` is removed, groups alike."""
    return float(np.mean([np.mean(np.abs(angle_diff(g, offset))) for g in groups]))
