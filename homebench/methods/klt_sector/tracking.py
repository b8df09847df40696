"""Shi-Tomasi corners and pyramidal KLT tracking on unfolded panoramas (seed 000, section 2.2-2.3).

Corners are Shi-Tomasi's "good features to track" (eq. 2-3: the smaller eigenvalue of the
gradient matrix Z over a ``block_size`` x ``block_size`` neighbourhood above a threshold ``t``);
``t`` is OpenCV's relative one, ``quality_level`` times the image's largest such eigenvalue.
Tracking is OpenCV's pyramidal Lucas-Kanade (the translational model of eq. 4-5, solved
coarse to fine).

An unfolded panorama wraps around in azimuth: column ``width`` is column 0. Both detection and
tracking run on the image padded circularly by :meth:`KltTracker.pad_width` columns on each side,
and positions are wrapped back to ``[0, width)``, so a corner that crosses column 0 keeps its
track. Rows do not wrap (top and bottom are real borders).

Prealignment (``prealign``, a departure, off by default): before each step the global column
shift between the two panoramas (the peak of their circular cross-correlation along the rows)
seeds every track's LK search. The paper's robot turns at most 3 deg/s while tracking at frame
rate, so its inter-frame shift is about zero and the paper needs none. Turn it on where views
are turned by arbitrary angles between steps — the benchmark's no-compass tests, which rotate
current views by whole columns — since the panoramas are too short for a pyramid deep enough to
find shifts of tens of columns. It is the paper's own pose correction (section 2.3: features are
looked for around locations shifted by the heading change) applied at every step.

Life-cycle (section 2.3): a track is dropped when KLT loses it or when its window no longer
satisfies eq. 3. LK refuses a window whose gradient matrix has a smaller eigenvalue below
``min_eigen`` (OpenCV's ``minEigThreshold``: the eigenvalue divided by the window's pixel
count; default OpenCV's 1e-4): the forward pass tests the window in the previous image, and a
backward pass (the new position tracked back into the previous image) tests it in the new one,
which is where the paper applies eq. 3. An absolute threshold, unlike the detection's relative
one, so that new strong texture elsewhere in the image does not drop the tracks. With
``fb_threshold`` (a departure, off by default) the backward pass must also land within that
many pixels of where the track started (a patch that changed does not come back). New corners
are detected, away from the surviving ones, when fewer than ``min_tracks`` survive.

Positions are (u, v) = (column, row) pixels, float32, as everywhere in homebench.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param

F32Array = NDArray[np.float32]
IdArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Tracks:
    """Tracked corners in one panorama.

    ``ids`` (n,) int64: stable identities; ``positions`` (n, 2) float32: (column, row) pixels,
    column in [0, width); ``alive`` (n,) bool: still tracked; ``next_id``: the id the next new
    corner gets.
    """

    ids: IdArray
    positions: F32Array
    alive: BoolArray
    next_id: int

    @classmethod
    def start(cls, corners: F32Array) -> Tracks:
        """Fresh tracks (ids 0 .. n-1, all alive) at ``corners`` (shape (n, 2))."""
        n = len(corners)
        positions = np.asarray(corners, dtype=np.float32).reshape(n, 2)
        return cls(np.arange(n, dtype=np.int64), positions, np.ones(n, dtype=bool), n)

    def __len__(self) -> int:
        return len(self.ids)

    @property
    def n_alive(self) -> int:
        return int(np.count_nonzero(self.alive))

    def survivors(self) -> Tracks:
        """Only the rows that are alive."""
        keep = self.alive
        return Tracks(self.ids[keep], self.positions[keep], self.alive[keep], self.next_id)


def circular_column_distance(a: F32Array, b: F32Array, width: int) -> NDArray[np.float64]:
    """Pixel distance between positions ``a`` and ``b`` (shapes (..., 2)), columns wrapping."""
    du = np.abs(np.asarray(a, np.float64)[..., 0] - np.asarray(b, np.float64)[..., 0]) % width
    dv = np.asarray(a, np.float64)[..., 1] - np.asarray(b, np.float64)[..., 1]
    return np.hypot(np.minimum(du, width - du), dv)


_OPENCV = "not stated; OpenCV's usual value"


@documented
@dataclass(frozen=True)
class KltTracker:
    """Detection and step-by-step tracking of corners in a sequence of panoramas (uint8)."""

    max_corners: int = param(
        150,
        "Corners detected in a view (and the most kept alive when replenishing).",
        reading="not stated; the paper kept at least 80 features between intermediate "
        "positions, in larger images",
    )
    quality_level: float = param(
        0.01,
        "Eq. 3's threshold t, relative: times the image's largest smaller eigenvalue.",
        reading=_OPENCV,
    )
    min_distance: float = param(
        5.0, "Least distance between detected corners (pixels).", reading=_OPENCV
    )
    block_size: int = param(7, "N of eq. 2's N x N neighbourhood (pixels).", reading=_OPENCV)
    window_size: int = param(21, "LK window (pixels, square).", reading=_OPENCV)
    pyramid_levels: int = param(
        3,
        "LK pyramid levels above the image (the coarsest is image / 2**levels).",
        reading="the paper's KLT (Tomasi and Kanade) solves eq. 4-5 at one resolution; "
        "OpenCV's pyramidal LK with its default depth, which the paper's small inter-frame "
        "displacements do not need and do not mind",
    )
    fb_threshold: float | None = param(
        None,
        "Forward-backward check: drop a track whose backward pass lands farther than this from "
        "its start (pixels); null: no check.",
        paper="drops a feature when KLT loses it or eq. 3 fails (section 2.3), without a "
        "forward-backward check; the check drops features whose patch changed, which KLT may "
        "otherwise follow to a wrong place",
    )
    min_eigen: float = param(
        1e-4,
        "Eq. 3's drop threshold for tracks: LK's minEigThreshold (smaller eigenvalue / pixels).",
        reading="the paper's t has no value; OpenCV's default",
    )
    prealign: bool = param(
        False,
        "Seed every LK search with the global column shift between the two views; turn on for "
        "no-compass tests with rotated current views.",
        paper="tracks at frame rate while turning at most 3 deg/s, so no shift needs finding",
    )
    min_tracks: int = param(
        50,
        "Detect new corners when fewer tracks survive a step.",
        reading="not stated; new features appear during the journey (Fig. 3)",
    )

    def __post_init__(self) -> None:
        check_fields(self)
        if self.max_corners < 1 or self.min_tracks < 0:
            raise ConfigError("klt: max_corners must be >= 1 and min_tracks >= 0")
        if not 0.0 < self.quality_level < 1.0 or self.min_eigen < 0:
            raise ConfigError("klt: need 0 < quality_level < 1 and min_eigen >= 0")
        if self.block_size < 3 or self.window_size < 3 or self.pyramid_levels < 0:
            raise ConfigError("klt: block_size and window_size >= 3, pyramid_levels >= 0")
        if self.min_distance < 0 or not (self.fb_threshold is None or self.fb_threshold > 0):
            raise ConfigError("klt: need min_distance >= 0 and fb_threshold > 0 or null")

    def pad_width(self, width: int) -> int:
        """Columns of circular padding on each side: the LK window at the coarsest level."""
        return min(width, (self.window_size // 2 + 1) * 2**self.pyramid_levels)

    def _padded(self, image: NDArray[np.uint8]) -> tuple[NDArray[np.uint8], int]:
        if image.ndim != 2 or image.dtype != np.uint8:
            raise ValueError(f"klt: need a grey uint8 image, got {image.dtype} {image.shape}")
        pad = self.pad_width(image.shape[1])
        return np.concatenate([image[:, -pad:], image, image[:, :pad]], axis=1), pad

    def detect(
        self, image: NDArray[np.uint8], existing: F32Array | None = None, limit: int | None = None
    ) -> F32Array:
        """Up to ``limit`` (default ``max_corners``) corners, shape (m, 2), best first.

        Corners closer than ``min_distance`` to ``existing`` positions (shape (k, 2)) or to a
        better new corner (columns wrapping) are left out.
        """
        width = image.shape[1]
        limit = self.max_corners if limit is None else limit
        existing = np.zeros((0, 2), np.float32) if existing is None else existing
        if limit < 1:
            return np.zeros((0, 2), np.float32)
        padded, pad = self._padded(image)
        mask = np.zeros(padded.shape, np.uint8)
        mask[:, pad : pad + width] = 255
        radius = max(1, round(self.min_distance))
        for u, v in existing:
            for copy in (u - width, u, u + width):
                cv2.circle(mask, (round(float(copy)) + pad, round(float(v))), radius, 0, -1)
        found = cv2.goodFeaturesToTrack(
            padded,
            maxCorners=limit + len(existing),
            qualityLevel=self.quality_level,
            minDistance=self.min_distance,
            mask=mask,
            blockSize=self.block_size,
        )
        if found is None:
            return np.zeros((0, 2), np.float32)
        candidates = found.reshape(-1, 2) - np.float32([pad, 0])
        kept: list[F32Array] = []
        taken = existing.astype(np.float32)
        for corner in candidates:
            if len(kept) == limit:
                break
            if np.all(circular_column_distance(taken, corner, width) >= self.min_distance):
                kept.append(corner)
                taken = np.vstack([taken, corner[None]])
        return np.asarray(kept, np.float32).reshape(-1, 2)

    def _flow(
        self,
        source: NDArray[np.uint8],
        target: NDArray[np.uint8],
        points: F32Array,
        shift: int,
        pad: int,
    ) -> tuple[F32Array, BoolArray]:
        """LK from ``source`` to ``target`` (padded images) of ``points`` (n, 2, padded coords).

        Each search starts ``shift`` columns from its point, wrapped into the original span.
        """
        width = source.shape[1] - 2 * pad
        guess = points.copy()
        guess[:, 0] = (points[:, 0] - pad + shift) % width + pad
        moved, status, _ = cv2.calcOpticalFlowPyrLK(
            source,
            target,
            points.reshape(-1, 1, 2),
            guess.reshape(-1, 1, 2),
            winSize=(self.window_size, self.window_size),
            maxLevel=self.pyramid_levels,
            criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, 0.01),
            flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
            minEigThreshold=self.min_eigen,
        )
        return moved.reshape(-1, 2), status.ravel().astype(bool)

    def step(
        self,
        previous: NDArray[np.uint8],
        tracks: Tracks,
        image: NDArray[np.uint8],
        replenish: bool = True,
    ) -> Tracks:
        """Tracks in ``image`` from the ``tracks`` of the ``previous`` image (same shape).

        Rows of the result: the tracks alive in ``tracks`` (``alive`` says whether they
        survived this step; a lost track keeps its last position) followed by the corners born
        in this step (only when ``replenish`` and fewer than ``min_tracks`` survived).
        """
        if previous.shape != image.shape:
            raise ValueError(f"klt: image shapes differ: {previous.shape} vs {image.shape}")
        height, width = image.shape
        current = tracks.survivors()
        src, pad = self._padded(previous)
        dst, _ = self._padded(image)
        offset = np.float32([pad, 0])
        positions = current.positions.copy()
        alive = np.zeros(len(current), dtype=bool)
        if len(current):
            shift = column_shift(previous, image) if self.prealign else 0
            start = current.positions + offset
            moved, forward_ok = self._flow(src, dst, start, shift, pad)
            back, backward_ok = self._flow(dst, src, moved, -shift, pad)
            inside = (
                (moved[:, 0] >= 0)
                & (moved[:, 0] <= dst.shape[1] - 1)
                & (moved[:, 1] >= 0)
                & (moved[:, 1] <= height - 1)
            )
            alive = forward_ok & backward_ok & inside
            if self.fb_threshold is not None:
                alive &= circular_column_distance(back, start, width) <= self.fb_threshold
            new = moved - offset
            new[:, 0] %= width
            positions[alive] = new[alive]
        result = Tracks(current.ids, positions, alive, current.next_id)
        if replenish and result.n_alive < self.min_tracks:
            born = self.detect(image, positions[alive], self.max_corners - result.n_alive)
            result = _append(result, born)
        return result


def column_shift(previous: NDArray[np.uint8], image: NDArray[np.uint8]) -> int:
    """Whole columns (in [-width/2, width/2)) by which ``image`` is ``previous`` turned.

    The peak of the circular cross-correlation along the rows of the two panoramas (same shape
    (height, width)), each row's mean removed: ``image[:, c + shift] ~ previous[:, c]``.
    """
    a = previous.astype(np.float64)
    b = image.astype(np.float64)
    a -= a.mean(axis=1, keepdims=True)
    b -= b.mean(axis=1, keepdims=True)
    spectrum = np.sum(np.conj(np.fft.rfft(a, axis=1)) * np.fft.rfft(b, axis=1), axis=0)
    correlation = np.fft.irfft(spectrum, n=image.shape[1])
    width = image.shape[1]
    return (int(np.argmax(correlation)) + width // 2) % width - width // 2


def _append(tracks: Tracks, corners: F32Array) -> Tracks:
    """``tracks`` with new alive tracks at ``corners`` (m, 2) under fresh ids."""
    m = len(corners)
    return Tracks(
        np.concatenate([tracks.ids, tracks.next_id + np.arange(m, dtype=np.int64)]),
        np.concatenate([tracks.positions, corners.astype(np.float32)]),
        np.concatenate([tracks.alive, np.ones(m, dtype=bool)]),
        tracks.next_id + m,
    )
