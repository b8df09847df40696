"""SIFT-landmark homing (seed 001): SIFT landmarks, mismatch elimination, warping equations.

Pipeline of :meth:`Sift.home` (seed 001, Figure 5):

1. **Landmarks** (:meth:`Sift.describe`): OpenCV SIFT on the raw catadioptric image (the paper's
   choice), masked to the mirror's annulus, with Table 1's S = 5 scale layers and DoG threshold
   0.04 / S. OpenCV divides ``contrastThreshold`` by ``nOctaveLayers`` before applying it (its
   documentation: "The contrast threshold will be divided by nOctaveLayers when the filtering is
   applied"), so ``contrastThreshold = 0.04`` with ``nOctaveLayers = 5`` applies exactly the
   paper's 0.04 / 5 (grey levels scaled to [0, 1]). Each landmark keeps its azimuth and its side
   of the horizon circle (eq. 8), both from :mod:`homebench.geometry`.
2. **Matching** (:mod:`~homebench.methods.sift.matching`): each goal landmark to its nearest
   current one with Lowe's ratio test (the paper names no matching rule), optionally
   cross-checked. OpenCV returns one keypoint per dominant orientation, as Lowe's SIFT does, so
   a place can be matched twice; the paper counts every match (``distinct_matches`` merges
   them, an option).
3. **Mismatch elimination** (:mod:`~homebench.methods.sift.elimination`): constraint 1, then
   constraint 2 (nR = 5, VTH = 4); each stage is a switch, so the paper's P (both on) and PN
   (both off) are two config entries of this one method.
4. **Homing angle** (:mod:`~homebench.methods.sift.solver`): eq. 3 in closed form for every
   landmark triple (or a seeded sample of ``max_triples`` of them), alpha and psi by exact
   circular least squares (eq. 5-6), ``beta = pi + alpha - psi`` (eq. 7). The estimate's
   ``rotation`` is psi, the heading change from goal to current (ccw); its ``score`` is the RMS
   circular deviation of the triples' alphas (radians, lower is better). Triples with rho = 0
   carry no alpha: identical views give a rotation and no direction.

Departures from the paper are options that default to the paper: ``ahead_filter``,
``distinct_matches``, ``cross_check`` (and the variant ``sift-unfolded``). Readings of what the
paper leaves open: ``edge_threshold``, ``sigma``, ``mask_annulus``, ``ratio``,
``horizon_tolerance_px``, ``max_triples`` and the root of eq. 3 (see the solver).

Fewer than 3 landmarks left, or no triple with a real solution, gives
:meth:`HomingEstimate.none` with the stage counts in its diagnostics; the stage counts are in
every estimate's diagnostics.

Validation (tests/test_validation_sift.py), on the paper's setting, landmarks on the raw
catadioptric image, and its headline that P beats PN where mismatches occur: rendered raw views
of a generated room, 6 places 0.3-1.2 m from the goal, mean AE P 5.1 deg, PN 11.6 deg; with
the descriptors of 30 % of each current view's landmarks swapped round (planted mismatches), P
8.2 deg, PN 55 deg. The exact case (camera-model landmarks): tests/test_sift.py.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry
from homebench.methods.base import HomingEstimate, ImageKind, View
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param
from homebench.methods.registry import register
from homebench.methods.sift.elimination import half_plane_constraint, horizon_constraint
from homebench.methods.sift.matching import match_descriptors
from homebench.methods.sift.solver import estimate_movement

#: Columns wrapped around each side of an unfolded panorama before detection, so that landmarks
#: at the seam are found and described with their whole neighbourhood.
SEAM_PAD = 32


@dataclass(frozen=True)
class SiftFeatures:
    """The SIFT landmarks of one image (picklable).

    ``positions``: pixels (u, v), shape (n, 2), float32. ``descriptors``: shape (n, 128),
    float32. ``azimuths``: radians, ccw, 0 = heading, shape (n,). ``sides``: eq. 8's
    ``gamma_IO`` (+1 above the horizon, -1 below, 0 on it), shape (n,), int8. ``period``: the
    image width when u wraps around (unfolded panorama), 0 for a raw image.
    """

    positions: NDArray[np.float32]
    descriptors: NDArray[np.float32]
    azimuths: NDArray[np.float64]
    sides: NDArray[np.int8]
    period: float = 0.0

    def __len__(self) -> int:
        return len(self.positions)


@lru_cache(maxsize=8)
def annulus_mask(geometry: CatadioptricGeometry) -> NDArray[np.uint8]:
    """OpenCV detection mask (height, width): 255 inside the mirror's annulus, 0 elsewhere."""
    mask = np.where(geometry.annulus_mask(), 255, 0).astype(np.uint8)
    mask.setflags(write=False)
    return mask


def panorama_sides(geometry: PanoramaGeometry, v: NDArray, tolerance: float) -> NDArray[np.int8]:
    """``gamma_IO`` of unfolded-panorama rows ``v``: +1 above the horizon, -1 below, 0 within
    ``tolerance`` rows of it."""
    offset = geometry.row_to_elevation(v) / geometry.row_step  # rows above the horizon
    return np.where(np.abs(offset) <= tolerance, 0, np.sign(offset)).astype(np.int8)


@dataclass(frozen=True)
class SiftHoming:
    """What ``sift`` and ``sift-unfolded`` share: the parameters that apply to both kinds of
    image, the detector and :meth:`home`; each describes its own kind of image."""

    name: ClassVar[str]

    n_octave_layers: int = param(5, "S: scale layers per octave (Table 1; Lowe's 3).")
    contrast_threshold: float = param(
        0.04,
        "T_DoG x S: OpenCV divides it by n_octave_layers, so 0.04 applies Table 1's 0.04 / S "
        "(grey levels in [0, 1]).",
    )
    edge_threshold: float = param(
        10.0,
        "Lowe's edge-response threshold r.",
        reading="not stated; the paper changes only S and T_DoG from Lowe's (2004) settings, "
        "so Lowe's r = 10 stays",
    )
    sigma: float = param(
        1.6,
        "Blur of the first octave's base image (pixels).",
        reading="not stated; Lowe's (2004) 1.6, as for edge_threshold",
    )
    ratio: float = param(
        0.8,
        "Lowe's ratio test: nearest / second-nearest descriptor distance must be below it.",
        reading="the paper names no matching rule; Lowe's (2004) ratio test at his 0.8",
    )
    cross_check: bool = param(
        False,
        "Keep a match only if the goal landmark is also its current landmark's nearest.",
        paper="matches each goal landmark to its nearest current one, without a mutual check",
    )
    distinct_matches: bool = param(
        False,
        "Count a repeated (goal position, current position) match once.",
        paper="counts every match; SIFT gives one keypoint per dominant orientation (Lowe "
        "2004), so a place can match twice and then votes twice in constraint 2 and eq. 5",
    )
    horizon_constraint: bool = param(
        True, "Mismatch elimination by constraint 1 (eq. 8); off with the next one: PN."
    )
    horizon_tolerance_px: float = param(
        1.0,
        "Distance from the horizon circle (pixels; rows for sift-unfolded) that counts as on "
        "it (eq. 8's gamma_IO = 0).",
        reading="eq. 8's r_L = r_H never holds exactly for sub-pixel keypoints; read as within "
        "about a keypoint's localisation precision at the first octaves",
    )
    half_plane_constraint: bool = param(
        True, "Mismatch elimination by constraint 2 (eq. 9-10, after constraint 1)."
    )
    n_references: int = param(5, "nR: reference landmarks per tested pair (Table 1).")
    vote_threshold: int = param(4, "VTH: votes a pair needs to be kept (Table 1).")
    ahead_filter: bool = param(
        False,
        "Discard triples whose solution puts a landmark behind the robot on its ray.",
        paper="keeps every triple eq. 3 solves; true bearings never put a landmark behind, "
        "noisy and mismatched ones often do, so the filter removes many wrong triples",
    )
    max_triples: int | None = param(
        2000,
        "Landmark triples solved per pair: all of them when there are at most this many (or "
        "with null), else this many drawn uniformly, seeded by seed and the bearings.",
        reading="'a number of parameter sets ... can be obtained' (section 2): read as all "
        "triples, estimated by a uniform sample when there are more than max_triples (the "
        "estimate then moves by 2-4 deg over seeds at 0.3-1.2 m, below the method's own error; "
        "null solves all C(n, 3), whose cost grows as n**3)",
    )
    seed: int = param(0, "Seed of the triple sample (together with a checksum of the bearings).")

    def __post_init__(self) -> None:
        check_fields(self)
        checks = {
            "n_octave_layers must be >= 1": self.n_octave_layers >= 1,
            "contrast_threshold must be > 0": self.contrast_threshold > 0,
            "edge_threshold must be > 0": self.edge_threshold > 0,
            "sigma must be > 0": self.sigma > 0,
            "ratio must be in (0, 1]": 0 < self.ratio <= 1,
            "horizon_tolerance_px must be >= 0": self.horizon_tolerance_px >= 0,
            "n_references must be >= 1": self.n_references >= 1,
            "vote_threshold must be in [0, n_references]": (
                0 <= self.vote_threshold <= self.n_references
            ),
            "max_triples must be >= 1 or null": self.max_triples is None or self.max_triples >= 1,
            "seed must be >= 0": self.seed >= 0,
        }
        failed = [message for message, ok in checks.items() if not ok]
        if failed:
            raise ConfigError(f"{self.name}: {failed[0]}")

    def _detector(self) -> cv2.SIFT:
        return cv2.SIFT_create(
            nOctaveLayers=self.n_octave_layers,
            contrastThreshold=self.contrast_threshold,
            edgeThreshold=self.edge_threshold,
            sigma=self.sigma,
        )

    def home(self, current: SiftFeatures, goal: SiftFeatures) -> HomingEstimate:
        """Home direction at the current view towards the goal view (seed 001, eq. 3-7)."""
        ig, ic = match_descriptors(
            goal.descriptors, current.descriptors, self.ratio, self.cross_check
        )
        if self.distinct_matches:
            ig, ic = _distinct_pairs(goal.positions[ig], current.positions[ic], ig, ic)
        counts = {"n_matches": len(ig)}
        if self.horizon_constraint:
            keep = horizon_constraint(goal.sides[ig], current.sides[ic])
            ig, ic = ig[keep], ic[keep]
            counts["n_after_horizon"] = len(ig)
        if self.half_plane_constraint:
            keep = half_plane_constraint(
                goal.positions[ig],
                goal.azimuths[ig],
                current.azimuths[ic],
                self.n_references,
                self.vote_threshold,
                goal.period,
            )
            ig, ic = ig[keep], ic[keep]
            counts["n_after_half_plane"] = len(ig)
        n = len(ig)
        if n < 3:
            return HomingEstimate.none(n, reason="fewer than 3 landmarks", **counts)
        movement = estimate_movement(
            goal.azimuths[ig],
            current.azimuths[ic],
            self.max_triples,
            self.seed,
            ahead_filter=self.ahead_filter,
        )
        if movement is None:
            return HomingEstimate.none(n, reason="no triple with a real solution", **counts)
        return HomingEstimate(
            angle=movement.home_direction,
            rotation=movement.psi,
            n_landmarks=n,
            score=movement.alpha_rms,
            diagnostics={
                **counts,
                "n_triples": movement.n_triples,
                "n_valid_triples": movement.n_valid,
                "n_direction_triples": movement.n_direction,
                "alpha": movement.alpha,
                "psi": movement.psi,
                "rho_median": movement.rho_median,
            },
        )


@register
@documented
@dataclass(frozen=True)
class Sift(SiftHoming):
    """SIFT-landmark homing on raw catadioptric images; defaults: seed 001, Table 1."""

    name: ClassVar[str] = "sift"
    image_kind: ClassVar[ImageKind] = "raw"

    mask_annulus: bool = param(
        True,
        "Detect only inside the mirror's annulus.",
        reading="the paper detects on the raw image without saying where; landmarks are scene "
        "points, which appear only inside the annulus (outside are the rim and the camera, "
        "which turn with the robot and would match at unchanged bearings)",
    )

    def describe(self, view: View) -> SiftFeatures:
        """SIFT landmarks of a raw catadioptric view, with bearings and sides."""
        geometry = view.geometry
        if not isinstance(geometry, CatadioptricGeometry):
            raise ConfigError(f"{self.name}: needs a raw image, got an unfolded panorama")
        mask = annulus_mask(geometry) if self.mask_annulus else None
        keypoints, descriptors = self._detector().detectAndCompute(view.image, mask)
        positions = _positions(keypoints)
        u, v = positions[:, 0], positions[:, 1]
        azimuths, _ = geometry.pixel_to_bearing(u, v)
        sides = geometry.horizon_side(u, v, self.horizon_tolerance_px)
        return _features(positions, descriptors, azimuths, sides)


@register
@documented
@dataclass(frozen=True)
class SiftUnfolded(SiftHoming):
    """The same method on the unfolded panorama (an option; the paper uses the raw image).

    Detection wraps ``SEAM_PAD`` columns around the seam; the horizon tolerance is in rows.
    """

    name: ClassVar[str] = "sift-unfolded"
    image_kind: ClassVar[ImageKind] = "unfolded"

    def describe(self, view: View) -> SiftFeatures:
        """SIFT landmarks of an unfolded panorama, with bearings and sides."""
        geometry = view.geometry
        if not isinstance(geometry, PanoramaGeometry):
            raise ConfigError(f"{self.name}: needs an unfolded panorama, got a raw image")
        pad = min(SEAM_PAD, geometry.width)
        padded = cv2.copyMakeBorder(view.image, 0, 0, pad, pad, cv2.BORDER_WRAP)
        keypoints, descriptors = self._detector().detectAndCompute(padded, None)
        positions = _positions(keypoints) - np.array([pad, 0], dtype=np.float32)
        inside = (positions[:, 0] >= 0) & (positions[:, 0] < geometry.width)
        positions = positions[inside]
        descriptors = descriptors[inside] if descriptors is not None else None
        azimuths = geometry.column_to_azimuth(positions[:, 0])
        sides = panorama_sides(geometry, positions[:, 1], self.horizon_tolerance_px)
        return _features(positions, descriptors, azimuths, sides, float(geometry.width))


def _features(
    positions: NDArray[np.float32],
    descriptors: NDArray[np.float32] | None,
    azimuths: NDArray[np.float64],
    sides: NDArray[np.int8],
    period: float = 0.0,
) -> SiftFeatures:
    """The features of one image; no descriptors (OpenCV's None: no keypoints) as (0, 128)."""
    if descriptors is None:
        descriptors = np.empty((0, 128), dtype=np.float32)
    return SiftFeatures(positions, descriptors.astype(np.float32), azimuths, sides, period)


def _positions(keypoints: tuple[cv2.KeyPoint, ...]) -> NDArray[np.float32]:
    """Keypoint positions (u, v), shape (n, 2), float32."""
    return np.array([kp.pt for kp in keypoints], dtype=np.float32).reshape(-1, 2)


def _distinct_pairs(
    goal_positions: NDArray[np.float32],
    current_positions: NDArray[np.float32],
    goal_index: NDArray[np.intp],
    current_index: NDArray[np.intp],
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The matches whose (goal position, current position) is new, in their original order."""
    if len(goal_index) == 0:
        return goal_index, current_index
    keys = np.hstack([goal_positions, current_positions])
    _, first = np.unique(keys, axis=0, return_index=True)
    first = np.sort(first)
    return goal_index[first], current_index[first]
