"""KLT-sector homing (seed 000): corners tracked from the goal to the current view, sector law.

``describe`` keeps the unfolded panorama and its Shi-Tomasi corners. ``home`` tracks the goal's
corners with pyramidal KLT through the intermediate views of ``route`` (from the goal towards
the current place; the paper gets correspondences by tracking along the path, section 2.2) and
into the current view, converts both ends to bearings (eq. 1), keeps the features that pass the
ordering filter (longest common subsequence of the two retinotopic orders) and sums the sector
vectors into M (section 2.1, see :mod:`homebench.methods.klt_sector.sector_law`). The home
direction is
M's direction in the current robot frame; the rotation is the median angular shift of the kept
features (the paper's pose correction, exact only where the two views were taken at one place).
Fewer than ``min_features`` kept features give :meth:`HomingEstimate.none`; ``M = 0`` (identical
views) gives the rotation and no direction.

Departures (options, off by default): the tracker's ``prealign`` and ``fb_threshold`` (see
:mod:`homebench.methods.klt_sector.tracking`). Readings: ``lcs`` (where a circular order starts),
``bisectors`` (which view's sector bisector), ``goal_threshold``, ``route_step`` and the
tracker's unstated settings.

The engine decides the route: ``uses_route`` tells it to pass the intermediate views, taken
``route_step`` grid units apart along the straight line from the goal to the current place
(0: none, track directly from the goal to the current view), or along the tree of such routes
(``route_shape``, see :mod:`homebench.evaluation.grid_routes`); route views are described by
:meth:`KltSector.describe_route`, without corners.

Validation (tests/test_validation_klt_sector.py), on the paper's scene, the corners of an
office: with the exact bearings of a generated room's 240 object corners, the sector law
applied step by step converges to within 1.2 mm from 0.5-2 m away; homing a route through its
waypoints in reverse, bearings with 0.2 deg of noise, ends 3-7 mm from home after 2 m and 3-5
mm after 12.6 m (sub-centimetre, not growing with the route, as the paper). End to end
(rendered views, KLT tracking, life-cycles): the route experiment, configs/klt_route.yaml.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import PanoramaGeometry
from homebench.methods.base import HomingEstimate, ImageKind, RouteShape, View
from homebench.methods.klt_sector.sector_law import (
    MIN_FEATURES,
    BisectorFrame,
    LcsOrder,
    bearings,
    goal_reached,
    heading_change,
    motion_vector,
    order_filter,
)
from homebench.methods.klt_sector.tracking import KltTracker, Tracks
from homebench.methods.param_types import check_fields
from homebench.methods.params import documented, param, same_as
from homebench.methods.registry import register

F32Array = NDArray[np.float32]

#: Route prefixes whose tracks one method instance keeps (a job's goal and its routes).
ROUTE_CACHE_SIZE = 4096
#: Tracker parameters the method exposes (replenishing plays no part between two views).
_TRACKER_FIELDS = tuple(f.name for f in fields(KltTracker) if f.name != "min_tracks")


@dataclass(frozen=True)
class KltFeatures:
    """One described view: the panorama (height, width) uint8, its geometry, its corners (n, 2),
    and a digest of the image that names the view in the route-tracking cache ("" = none)."""

    image: NDArray[np.uint8]
    geometry: PanoramaGeometry
    corners: F32Array
    digest: str = ""


@register
@documented
@dataclass(frozen=True)
class KltSector:
    """KLT tracking + sector law (seed 000); tracker parameters as in :class:`KltTracker`."""

    name: ClassVar[str] = "klt-sector"
    image_kind: ClassVar[ImageKind] = "unfolded"
    uses_route: ClassVar[bool] = True
    preload_modules: ClassVar[tuple[str, ...]] = (
        "homebench.methods.klt_sector.sector_law_kernels",
        "homebench.methods.jit_setup",
    )

    route_step: float = param(
        0.5,
        "Grid units between the views tracked through from the goal to the current place (0: "
        "track directly).",
        reading="the paper tracks at frame rate along the path (section 2.2); a grid database "
        "has views every grid unit, and 0.5 units (15 cm on Vardy's grid) shifts features by a "
        "few columns per step, which KLT follows with few losses (tracking directly over more "
        "than about 1 m gives wrong correspondences)",
    )
    route_shape: RouteShape = param(
        "tree",
        "Routes from the goal: the tree of routes (each view's route is the route to the last "
        "view before it on the straight line, then that view) or the straight line itself.",
        reading="the paper tracks along the path the robot drove from the goal; a grid "
        "database has none: 'tree' follows the line to within about a grid unit and extends "
        "a shorter route of the same goal, so the goal's corners are tracked once per grid "
        "position (one step per view instead of a whole route per pair); 'line' snaps the "
        "straight line itself",
    )
    max_corners: int = same_as(KltTracker, "max_corners")
    quality_level: float = same_as(KltTracker, "quality_level")
    min_distance: float = same_as(KltTracker, "min_distance")
    block_size: int = same_as(KltTracker, "block_size")
    window_size: int = same_as(KltTracker, "window_size")
    pyramid_levels: int = same_as(KltTracker, "pyramid_levels")
    fb_threshold: float | None = same_as(KltTracker, "fb_threshold")
    min_eigen: float = same_as(KltTracker, "min_eigen")
    prealign: bool = same_as(KltTracker, "prealign")
    min_features: int = param(
        MIN_FEATURES, "Fewest features left by the ordering filter that give an estimate (>= 3)."
    )
    goal_threshold: float = param(
        0.02,
        "Stop test on |M| (radians; diagnostic goal_reached).",
        reading="the paper's 'predefined threshold' has no value; |M| grows with the distance "
        "and the number of features, and 0.02 is |M| 1.6 cm from the goal with ~70 features on "
        "the analytic arena",
    )
    bisectors: BisectorFrame = param(
        "current",
        "Frame of the sector bisectors: the current view's, or the goal view's turned by the "
        "estimated heading change.",
        reading="'a vector parallel to the bisector of this sector' does not say in which view; "
        "the current one, in which the robot acts and which needs no compass",
    )
    lcs: LcsOrder = param(
        "circular",
        "Ordering filter: longest common subsequence of the circular orders (any start) or of "
        "the linear orders read from column 0 of each panorama.",
        reading="'features that do not appear in the same order in panoramas' are dropped by "
        "an LCS of two sequences; a panorama's order is circular and where the sequences start "
        "is not said: any start, as the order itself has none (linear drops features that "
        "cross column 0 between the views, though they kept their order)",
    )
    # Tracks of the goal's corners through route prefixes, keyed by the views' digests: the
    # currents of one goal share their first route views. Not a parameter.
    _route_tracks: dict[tuple[str, ...], Tracks] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        check_fields(self)
        self.tracker  # noqa: B018  (validates the tracker's parameters)
        if self.route_step < 0 or self.goal_threshold < 0:
            raise ConfigError("klt-sector: route_step and goal_threshold must be >= 0")
        if self.min_features < MIN_FEATURES:
            raise ConfigError(f"klt-sector: min_features must be >= {MIN_FEATURES}")

    @property
    def tracker(self) -> KltTracker:
        return KltTracker(**{name: getattr(self, name) for name in _TRACKER_FIELDS})

    def describe(self, view: View) -> KltFeatures:
        """The panorama and its Shi-Tomasi corners."""
        bare = self.describe_route(view)
        return replace(bare, corners=self.tracker.detect(view.image))

    def describe_route(self, view: View) -> KltFeatures:
        """A view of a route: the panorama without corners (tracking reads only the goal's)."""
        if not isinstance(view.geometry, PanoramaGeometry):
            raise ConfigError("klt-sector needs unfolded panoramas, got a raw image")
        digest = hashlib.blake2b(view.image.tobytes(), digest_size=16).hexdigest()
        return KltFeatures(view.image, view.geometry, np.zeros((0, 2), np.float32), digest)

    def correspondences(
        self, current: KltFeatures, goal: KltFeatures, route: Sequence[KltFeatures] = ()
    ) -> tuple[F32Array, F32Array]:
        """Positions (m, 2) of the goal corners that survive tracking, in the goal and current.

        Tracks the goal's corners through ``route`` (goal towards current) into ``current``.
        """
        views = (*route, current)
        for view in views:
            if view.image.shape != goal.image.shape or view.geometry != goal.geometry:
                raise ValueError("klt-sector: the views of a route must share one geometry")
        tracks = self._through_route(goal, views)
        return goal.corners[tracks.ids], tracks.positions

    def _through_route(self, goal: KltFeatures, route: Sequence[KltFeatures]) -> Tracks:
        """The goal's corners tracked through ``route`` (its last view: the current one),
        reusing the longest cached prefix.

        The routes from one goal form a tree (the straight lines to the currents share their
        first views, and a current is often a view on the route to a farther one): each edge
        is tracked once. Identical to tracking from scratch (tracking is deterministic); views
        without a digest are never cached.
        """
        keys = (goal.digest, *(view.digest for view in route))
        cacheable = all(keys)
        tracks, done = Tracks.start(goal.corners), 0
        if cacheable:
            for n in range(len(route), 0, -1):
                if (hit := self._route_tracks.get(keys[: n + 1])) is not None:
                    tracks, done = hit, n
                    break
        views = (goal, *route)
        tracker = self.tracker
        for k in range(done, len(route)):
            tracks = tracker.step(views[k].image, tracks, views[k + 1].image, replenish=False)
            tracks = tracks.survivors()
            if cacheable:
                if len(self._route_tracks) >= ROUTE_CACHE_SIZE:
                    self._route_tracks.clear()
                self._route_tracks[keys[: k + 2]] = tracks
        return tracks

    def home(
        self, current: KltFeatures, goal: KltFeatures, route: Sequence[KltFeatures] = ()
    ) -> HomingEstimate:
        """Home direction from the sector law on the features tracked from goal to current."""
        at_goal, at_current = self.correspondences(current, goal, route)
        theta_goal = bearings(at_goal[:, 0], goal.geometry)
        theta_current = bearings(at_current[:, 0], current.geometry)
        kept = order_filter(at_current[:, 0], at_goal[:, 0], circular=self.lcs == "circular")
        n_kept = int(np.count_nonzero(kept))
        info = {"n_tracked": len(at_goal), "route_length": len(route)}
        if n_kept < self.min_features:
            return HomingEstimate.none(n_kept, reason="too few features", **info)
        theta_current, theta_goal = theta_current[kept], theta_goal[kept]
        motion = motion_vector(theta_current, theta_goal, self.bisectors)
        length = float(np.hypot(*motion))
        return HomingEstimate(
            angle=float(np.arctan2(motion[1], motion[0])) if length > 0 else None,
            rotation=heading_change(theta_current, theta_goal),
            n_landmarks=n_kept,
            score=length,
            diagnostics={
                **info,
                "motion": (float(motion[0]), float(motion[1])),
                "goal_reached": goal_reached(motion, self.goal_threshold),
            },
        )
