"""Angles, frames, grid coordinates and camera models: the one place conventions live.

Conventions (every other module asks this one):

- **World frame**: metres; x to the right, y up (on a map), z up from the floor. A world
  direction is an angle counter-clockwise from +x, in radians.
- **Pose**: position (x, y) and heading, the world direction the robot faces.
- **Azimuth**: a direction in the robot frame, counter-clockwise, 0 = the robot's heading.
  ``world direction = heading + azimuth``.
- **Elevation**: angle above the camera's horizontal plane, radians, positive up.
- **Grid**: index (i, j) sits at ``(x0 + i * spacing, y0 + j * spacing)``; i runs along x
  (0 .. nx-1), j along y (0 .. ny-1), as in Vardy's ``X_Y`` file names.
- **Pixels**: (u, v) = (column, row); the centre of pixel (u, v) is at integer coordinates
  (OpenCV's remap convention); v grows downwards.
- **Unfolded panorama**: column p has azimuth ``direction * 2*pi*(p - zero_column) / width``;
  rows span ``elevation_top`` (upper edge of row 0) to ``elevation_bottom`` (lower edge of the
  last row) linearly.
- **Raw catadioptric image**: a centre, a radial profile (radius -> elevation, monotone), and the
  image angle (counter-clockwise as displayed, from +u) at which azimuth 0 appears, with the
  direction in which azimuth grows on screen (a mirror seen from below usually flips it).

All angles are radians unless a name ends in ``_deg``. Angle arrays may be any shape.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

TWO_PI = 2.0 * np.pi
Direction = Literal["ccw", "cw"]
FloatArray = NDArray[np.float64]


# --------------------------------------------------------------------------- angles


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Wrap angles to [-pi, pi). Shape is preserved."""
    a = np.asarray(angle, dtype=np.float64)
    return (a + np.pi) % TWO_PI - np.pi


def wrap_positive(angle: ArrayLike) -> FloatArray:
    """Wrap angles to [0, 2*pi). Shape is preserved."""
    return np.asarray(angle, dtype=np.float64) % TWO_PI


def angle_diff(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Signed difference ``a - b`` wrapped to [-pi, pi)."""
    return wrap_angle(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64))


def angular_error(estimate: ArrayLike, truth: ArrayLike) -> FloatArray:
    """Unsigned angular error ``|wrap(estimate - truth)|`` in [0, pi] (seed 001, eq. 6 and 11)."""
    return np.abs(angle_diff(estimate, truth))


def circular_mean(angles: ArrayLike, weights: ArrayLike | None = None) -> float:
    """Direction of the (weighted) mean unit vector of ``angles`` (shape (n,)); NaN if n == 0."""
    a = np.asarray(angles, dtype=np.float64).ravel()
    if a.size == 0:
        return float("nan")
    w = np.ones_like(a) if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    return float(np.arctan2(np.sum(w * np.sin(a)), np.sum(w * np.cos(a))))


def robot_to_world(azimuth: ArrayLike, heading: ArrayLike) -> FloatArray:
    """World direction of a robot-frame azimuth seen by a robot with ``heading``."""
    return wrap_angle(np.asarray(heading) + np.asarray(azimuth))


def world_to_robot(direction: ArrayLike, heading: ArrayLike) -> FloatArray:
    """Robot-frame azimuth of a world ``direction`` for a robot with ``heading``."""
    return wrap_angle(np.asarray(direction) - np.asarray(heading))


def world_to_robot_xy(vector: ArrayLike, heading: float) -> FloatArray:
    """A world-frame vector (..., 2) in the frame of a robot with ``heading`` (x ahead, y
    left): the vector turned by ``-heading``."""
    v = np.asarray(vector, dtype=np.float64)
    c, s = np.cos(heading), np.sin(heading)
    return np.stack([c * v[..., 0] + s * v[..., 1], -s * v[..., 0] + c * v[..., 1]], axis=-1)


def world_direction(from_xy: ArrayLike, to_xy: ArrayLike) -> FloatArray:
    """World direction from points ``from_xy`` to ``to_xy`` (shapes (..., 2)), in [-pi, pi]."""
    d = np.asarray(to_xy, dtype=np.float64) - np.asarray(from_xy, dtype=np.float64)
    return np.arctan2(d[..., 1], d[..., 0])


# --------------------------------------------------------------------------- poses and grids


@dataclass(frozen=True)
class Pose:
    """A robot pose in the world frame: position in metres, heading in radians."""

    x: float
    y: float
    heading: float = 0.0

    @property
    def xy(self) -> FloatArray:
        return np.array([self.x, self.y])

    def bearing_to(
        self, points: ArrayLike, camera_height: float = 0.0
    ) -> tuple[FloatArray, FloatArray]:
        """Azimuth and elevation of world points (shape (..., 3)) from a camera at this pose.

        The camera sits ``camera_height`` metres above the floor. Returns two arrays of shape (...).
        """
        p = np.asarray(points, dtype=np.float64)
        dx, dy, dz = p[..., 0] - self.x, p[..., 1] - self.y, p[..., 2] - camera_height
        azimuth = world_to_robot(np.arctan2(dy, dx), self.heading)
        elevation = np.arctan2(dz, np.hypot(dx, dy))
        return azimuth, elevation


@dataclass(frozen=True)
class Grid:
    """A regular capture grid: ``shape = (nx, ny)`` positions, ``spacing`` metres apart."""

    shape: tuple[int, int]
    spacing: float
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if self.shape[0] < 1 or self.shape[1] < 1:
            raise ValueError(f"grid shape must be positive, got {self.shape}")
        if not self.spacing > 0:
            raise ValueError(f"grid spacing must be positive, got {self.spacing}")

    @property
    def size(self) -> int:
        return self.shape[0] * self.shape[1]

    def position(self, i: ArrayLike, j: ArrayLike) -> FloatArray:
        """World position (x, y) in metres of grid index (i, j); shape (..., 2)."""
        x = self.origin[0] + np.asarray(i, dtype=np.float64) * self.spacing
        y = self.origin[1] + np.asarray(j, dtype=np.float64) * self.spacing
        return np.stack(np.broadcast_arrays(x, y), axis=-1)

    def nearest_index(self, xy: ArrayLike) -> NDArray[np.int64]:
        """Nearest grid index (i, j) of world points (shape (..., 2)), clipped to the grid."""
        p = np.asarray(xy, dtype=np.float64)
        ij = np.rint((p - np.asarray(self.origin)) / self.spacing).astype(np.int64)
        return np.clip(ij, 0, np.asarray(self.shape) - 1)

    def contains(self, i: int, j: int) -> bool:
        return 0 <= i < self.shape[0] and 0 <= j < self.shape[1]

    def indices(self) -> Iterator[tuple[int, int]]:
        """All grid indices, j fastest: (0,0), (0,1), ... (nx-1, ny-1)."""
        for i in range(self.shape[0]):
            for j in range(self.shape[1]):
                yield (i, j)

    @property
    def perimeter(self) -> float:
        """Perimeter of the grid's bounding rectangle in metres."""
        return 2.0 * ((self.shape[0] - 1) + (self.shape[1] - 1)) * self.spacing

    def pose(self, i: int, j: int, heading: float = 0.0) -> Pose:
        x, y = self.position(i, j)
        return Pose(float(x), float(y), heading)

    def present(self) -> NDArray[np.bool_]:
        """(nx, ny) mask of the positions that hold images: every one of a full grid."""
        return np.ones(self.shape, dtype=bool)


@dataclass(frozen=True, repr=False)
class HoledGrid(Grid):
    """A regular grid some of whose positions hold no image (a failed capture, a block cut
    from a larger grid whose positions it reads in another order): ``missing`` lists them,
    (i, j) inside the shape, sorted, fewer than every position. :meth:`indices`,
    :meth:`contains` and :attr:`size` leave them out, :meth:`nearest_index` gives the nearest
    position present, so that the engine plans, homes and steers over the positions present
    (a grid without holes is a :class:`Grid`: :func:`holed_grid`)."""

    missing: tuple[tuple[int, int], ...] = ()

    def __post_init__(self) -> None:
        super().__post_init__()
        missing = tuple(sorted({(int(i), int(j)) for i, j in self.missing}))
        if not missing or len(missing) >= super().size:
            raise ValueError(f"a grid of shape {self.shape} with holes misses 1 to all but one")
        if not all(super(HoledGrid, self).contains(i, j) for i, j in missing):
            raise ValueError(f"missing positions must lie inside the grid of shape {self.shape}")
        object.__setattr__(self, "missing", missing)

    @functools.cached_property
    def _holes(self) -> frozenset[tuple[int, int]]:
        return frozenset(self.missing)

    @functools.cached_property
    def _hash(self) -> int:
        return hash((self.shape, self.spacing, self.origin, self.missing))

    def __hash__(self) -> int:  # sources hash by their grid per view: once, not per view
        return self._hash

    def __repr__(self) -> str:
        return (
            f"HoledGrid(shape={self.shape}, spacing={self.spacing}, origin={self.origin}, "
            f"{len(self.missing)} missing)"
        )

    @property
    def size(self) -> int:
        """Positions present."""
        return self.shape[0] * self.shape[1] - len(self.missing)

    def contains(self, i: int, j: int) -> bool:
        return super().contains(i, j) and (i, j) not in self._holes

    def indices(self) -> Iterator[tuple[int, int]]:
        """The indices present, j fastest."""
        return (index for index in super().indices() if index not in self._holes)

    def present(self) -> NDArray[np.bool_]:
        return self._present.copy()

    @functools.cached_property
    def _present(self) -> NDArray[np.bool_]:
        mask = np.ones(self.shape, dtype=bool)
        mask[tuple(np.array(self.missing).T)] = False
        return mask

    def nearest_index(self, xy: ArrayLike) -> NDArray[np.int64]:
        """Nearest grid index (i, j) present of world points (shape (..., 2)), also off the
        grid: the full grid's (clipped), else, where that is missing, by a k-d tree."""
        p = np.asarray(xy, dtype=np.float64)
        ij = super().nearest_index(p)
        hole = ~self._present[ij[..., 0], ij[..., 1]]
        if hole.any():
            _, k = self._tree.query(p[hole])
            ij[hole] = self._present_ij[np.asarray(k, dtype=np.int64)]
        return ij

    @functools.cached_property
    def _present_ij(self) -> NDArray[np.int64]:
        return np.argwhere(self._present).astype(np.int64)

    @functools.cached_property
    def _tree(self) -> Any:
        from scipy.spatial import cKDTree  # imported where needed: most runs need none

        return cKDTree(self.position(self._present_ij[:, 0], self._present_ij[:, 1]))


def holed_grid(
    shape: tuple[int, int],
    spacing: float,
    origin: tuple[float, float],
    missing: Sequence[tuple[int, int]],
) -> Grid:
    """The grid of ``shape`` without the positions ``missing``: a :class:`Grid` where none
    is, so that full grids keep their fields and keys, else a :class:`HoledGrid`."""
    if not missing:
        return Grid(shape, spacing, origin)
    return HoledGrid(shape, spacing, origin, tuple(missing))


def missing_positions(grid: Grid) -> tuple[tuple[int, int], ...]:
    """The positions of ``grid``'s shape that hold no image (:class:`HoledGrid`), sorted."""
    return grid.missing if isinstance(grid, HoledGrid) else ()


@dataclass(frozen=True, repr=False)
class Places(Grid):
    """Posed places (a route, or any set of posed images): image ``k`` is addressed as grid
    index (k, 0) of an (n, 1) layout and sits at ``xy[k]`` (metres), so that the engine's
    grid-indexed planning, jobs and true home directions serve it unchanged. Build it with
    :meth:`of`. ``spacing`` is the median distance to the nearest other place (metres; 1
    where all places coincide), ``origin`` the first place: nominal, for messages only, as
    places have no neighbours along grid axes (no return ratio, catchment or grid maps)."""

    xy: tuple[tuple[float, float], ...] = ()

    @classmethod
    def of(cls, xy: ArrayLike) -> Places:
        """The places at ``xy`` (n, 2) metres, n >= 1, in that order."""
        points = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if len(points) < 1 or not np.all(np.isfinite(points)):
            raise ValueError("places need at least one pose, all finite")
        spacing = nearest_spacing(points)
        origin = (float(points[0, 0]), float(points[0, 1]))
        xy_tuple = tuple((float(x), float(y)) for x, y in points)
        return cls((len(points), 1), spacing, origin, xy_tuple)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape != (len(self.xy), 1):
            raise ValueError(f"places of shape {self.shape} need {self.shape[0]} poses")

    @functools.cached_property
    def points(self) -> FloatArray:
        """The places' positions, (n, 2) metres."""
        return np.asarray(self.xy, dtype=np.float64).reshape(-1, 2)

    @functools.cached_property
    def _hash(self) -> int:
        return hash((self.shape, self.xy))

    def __hash__(self) -> int:  # sources hash by their grid per view: once, not per pose
        return self._hash

    def __repr__(self) -> str:
        return f"Places({self.shape[0]} poses, from {self.origin})"

    def position(self, i: ArrayLike, j: ArrayLike) -> FloatArray:
        """World position (x, y) in metres of place i (j must be 0); shape (..., 2)."""
        k, _ = np.broadcast_arrays(np.asarray(i, dtype=np.int64), np.asarray(j))
        return self.points[k]

    def nearest_index(self, xy: ArrayLike) -> NDArray[np.int64]:
        """Index (k, 0) of the nearest place of world points (shape (..., 2))."""
        p = np.asarray(xy, dtype=np.float64)
        _, k = self._tree.query(p.reshape(-1, 2))
        k = np.asarray(k, dtype=np.int64).reshape(p.shape[:-1])
        return np.stack([k, np.zeros_like(k)], axis=-1)

    @functools.cached_property
    def _tree(self) -> Any:
        from scipy.spatial import cKDTree  # imported where needed: most runs need none

        return cKDTree(self.points)

    @property
    def perimeter(self) -> float:
        """Perimeter of the places' bounding rectangle in metres."""
        return 2.0 * float(np.sum(np.ptp(self.points, axis=0)))


def nearest_distances(points: FloatArray) -> FloatArray:
    """Distance (metres) from each of ``points`` (n, 2) to its nearest other point, shape (n,);
    those of points with another at the same place, or too far apart for floats, left out.
    O(n log n) by a k-d tree; empty for fewer than two points."""
    if len(points) < 2:
        return np.empty(0)
    from scipy.spatial import cKDTree  # imported where needed: most runs need none

    distances, _ = cKDTree(points).query(points, k=2)
    nearest = distances[:, 1]
    return nearest[(nearest > 0) & np.isfinite(nearest)]


def nearest_spacing(points: FloatArray) -> float:
    """Median of :func:`nearest_distances` of ``points`` (n, 2), metres; 1.0 when none is
    left (one point, or all at one place, or too far apart to measure)."""
    nearest = nearest_distances(points)
    spacing = float(np.median(nearest)) if nearest.size else 1.0
    return spacing if math.isfinite(spacing) and spacing > 0 else 1.0


def is_places(grid: Grid) -> bool:
    """Whether ``grid`` is :class:`Places` (posed images), not a regular grid."""
    return isinstance(grid, Places)


def grid_key(i: int, j: int) -> str:
    """The ``X_Y`` key of a grid position, as in Vardy's file names."""
    return f"{i}_{j}"


def parse_grid_key(key: str) -> tuple[int, int]:
    """Inverse of :func:`grid_key`; raises ValueError on anything else."""
    a, b = key.split("_")
    return int(a), int(b)


def home_direction(current_xy: ArrayLike, goal_xy: ArrayLike, heading: ArrayLike) -> FloatArray:
    """True home direction: azimuth of the goal seen from the current pose (shape (...))."""
    return world_to_robot(world_direction(current_xy, goal_xy), heading)


# --------------------------------------------------------------------------- camera models


def _sign(direction: Direction) -> float:
    if direction not in ("ccw", "cw"):
        raise ValueError(f"direction must be 'ccw' or 'cw', got {direction!r}")
    return 1.0 if direction == "ccw" else -1.0


def other_direction(direction: Direction) -> Direction:
    """The opposite azimuth direction: "cw" for "ccw" and the reverse."""
    return "cw" if _sign(direction) > 0 else "ccw"


@dataclass(frozen=True)
class HeadingConvention:
    """How another project writes headings: ``zero_deg`` is the world direction (degrees, ccw
    from +x) of a recorded heading of 0, ``direction`` the way recorded headings grow seen
    from above. homebench's own: zero 0, ccw; a compass bearing (clockwise from +y, "north"):
    zero 90, cw."""

    zero_deg: float = 0.0
    direction: Direction = "ccw"

    def __post_init__(self) -> None:
        _sign(self.direction)

    def to_world_deg(self, recorded_deg: ArrayLike) -> FloatArray:
        """World headings (degrees, ccw from +x) of ``recorded_deg`` (any shape)."""
        recorded = np.asarray(recorded_deg, dtype=np.float64)
        return self.zero_deg + _sign(self.direction) * recorded

    def from_world_deg(self, world_deg: ArrayLike) -> FloatArray:
        """Recorded headings (degrees, this convention) of world headings ``world_deg``."""
        world = np.asarray(world_deg, dtype=np.float64)
        return _sign(self.direction) * (world - self.zero_deg)


@dataclass(frozen=True)
class PanoramaGeometry:
    """An unfolded (cylindrical, equiangular) panorama of ``width`` x ``height`` pixels."""

    width: int
    height: int
    elevation_top: float
    elevation_bottom: float
    direction: Direction = "ccw"
    zero_column: float = 0.0

    def __post_init__(self) -> None:
        _sign(self.direction)
        if self.width < 1 or self.height < 1:
            raise ValueError(f"panorama size must be positive, got {self.width}x{self.height}")
        if not self.elevation_top > self.elevation_bottom:
            raise ValueError("elevation_top must be above elevation_bottom")

    @classmethod
    def square_pixels(
        cls, width: int, elevation_top: float, elevation_bottom: float
    ) -> PanoramaGeometry:
        """A ccw panorama whose height gives rows as tall (in angle) as columns are wide."""
        height = max(1, round(width * (elevation_top - elevation_bottom) / TWO_PI))
        return cls(width, height, elevation_top, elevation_bottom)

    @property
    def column_step(self) -> float:
        """Azimuth per column, radians."""
        return TWO_PI / self.width

    @property
    def row_step(self) -> float:
        """Elevation per row, radians."""
        return (self.elevation_top - self.elevation_bottom) / self.height

    def column_to_azimuth(self, column: ArrayLike) -> FloatArray:
        """Azimuth in [-pi, pi) of (fractional) columns."""
        p = np.asarray(column, dtype=np.float64)
        return wrap_angle(_sign(self.direction) * (p - self.zero_column) * self.column_step)

    def azimuth_to_column(self, azimuth: ArrayLike) -> FloatArray:
        """Fractional column in [0, width) of azimuths."""
        a = wrap_positive(_sign(self.direction) * np.asarray(azimuth, dtype=np.float64))
        return (a / self.column_step + self.zero_column) % self.width

    def row_to_elevation(self, row: ArrayLike) -> FloatArray:
        q = np.asarray(row, dtype=np.float64)
        return self.elevation_top - (q + 0.5) * self.row_step

    def elevation_to_row(self, elevation: ArrayLike) -> FloatArray:
        e = np.asarray(elevation, dtype=np.float64)
        return (self.elevation_top - e) / self.row_step - 0.5

    @property
    def horizon_row(self) -> float:
        """Fractional row of elevation 0."""
        return float(self.elevation_to_row(0.0))

    def bearing_grid(self) -> tuple[FloatArray, FloatArray]:
        """Azimuth and elevation of every pixel centre, each of shape (height, width)."""
        az = self.column_to_azimuth(np.arange(self.width))
        el = self.row_to_elevation(np.arange(self.height))
        return np.broadcast_to(az, (self.height, self.width)), np.broadcast_to(
            el[:, None], (self.height, self.width)
        )

    def columns_for_rotation(self, rotation: float) -> float:
        """Column shift that turns this panorama's robot by ``rotation`` (radians, ccw)."""
        return -_sign(self.direction) * rotation / self.column_step

    def turned(self, offset: float) -> PanoramaGeometry:
        """This model with every column's azimuth ``offset`` radians larger (the zero column
        moved, in [0, width))."""
        zero = (self.zero_column - _sign(self.direction) * offset / self.column_step) % self.width
        return replace(self, zero_column=float(zero))

    def horizon_at(self, row: float) -> PanoramaGeometry:
        """This model with elevation 0 at fractional ``row`` (both edges shifted alike)."""
        shift = float(self.row_to_elevation(row))
        return replace(
            self,
            elevation_top=self.elevation_top - shift,
            elevation_bottom=self.elevation_bottom - shift,
        )


@dataclass(frozen=True)
class CatadioptricGeometry:
    """A raw catadioptric image: centre, radial profile and azimuth orientation.

    ``radii`` (pixels, increasing) and ``elevations`` (radians, strictly monotone) sample the
    mirror's radial profile; elevation is linear between samples (two samples describe an
    equiangular mirror). The annulus between the first and last radius holds the image.
    """

    width: int
    height: int
    centre: tuple[float, float]
    radii: tuple[float, ...]
    elevations: tuple[float, ...]
    direction: Direction = "ccw"
    zero_angle: float = 0.0

    def __post_init__(self) -> None:
        _sign(self.direction)
        r, e = np.asarray(self.radii), np.asarray(self.elevations)
        if r.size < 2 or r.size != e.size:
            raise ValueError("radii and elevations need the same length, at least 2")
        if np.any(np.diff(r) <= 0):
            raise ValueError("radii must increase")
        de = np.diff(e)
        if not (np.all(de > 0) or np.all(de < 0)):
            raise ValueError("elevations must be strictly monotone along the radius")
        if not (min(e) < 0 < max(e)):
            raise ValueError("the radial profile must span the horizon (elevation 0)")

    @property
    def inner_radius(self) -> float:
        return float(self.radii[0])

    @property
    def outer_radius(self) -> float:
        return float(self.radii[-1])

    @property
    def up_is_outside(self) -> bool:
        """True when points above the horizon image outside the horizon circle."""
        return self.elevations[-1] > self.elevations[0]

    @property
    def horizon_radius(self) -> float:
        """Radius of the horizon circle (elevation 0), pixels."""
        return float(self.elevation_to_radius(0.0))

    def radius_to_elevation(self, radius: ArrayLike) -> FloatArray:
        """Elevation of radii (pixels); radii outside the annulus are extrapolated linearly."""
        r = np.asarray(radius, dtype=np.float64)
        return _interp_linear_extrapolate(r, np.asarray(self.radii), np.asarray(self.elevations))

    def elevation_to_radius(self, elevation: ArrayLike) -> FloatArray:
        e = np.asarray(elevation, dtype=np.float64)
        radii, elev = np.asarray(self.radii), np.asarray(self.elevations)
        order = np.argsort(elev)
        return _interp_linear_extrapolate(e, elev[order], radii[order])

    def turned(self, offset: float) -> CatadioptricGeometry:
        """This model with every pixel's azimuth ``offset`` radians larger (the image angle of
        azimuth 0 moved, wrapped to [-pi, pi))."""
        zero = wrap_angle(self.zero_angle - _sign(self.direction) * offset)
        return replace(self, zero_angle=float(zero))

    def horizon_at(self, radius: float) -> CatadioptricGeometry:
        """This model with elevation 0 at ``radius`` pixels: every elevation of the radial
        profile shifted alike (the mirror's angular range kept)."""
        shift = float(self.radius_to_elevation(radius))
        return replace(self, elevations=tuple(float(e) - shift for e in self.elevations))

    def pixel_to_bearing(self, u: ArrayLike, v: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Azimuth and elevation of pixels (u, v) (any shapes that broadcast)."""
        du = np.asarray(u, dtype=np.float64) - self.centre[0]
        dv = np.asarray(v, dtype=np.float64) - self.centre[1]
        image_angle = np.arctan2(-dv, du)  # counter-clockwise as displayed
        azimuth = wrap_angle(_sign(self.direction) * (image_angle - self.zero_angle))
        return azimuth, self.radius_to_elevation(np.hypot(du, dv))

    def bearing_to_pixel(
        self, azimuth: ArrayLike, elevation: ArrayLike
    ) -> tuple[FloatArray, FloatArray]:
        """Pixel coordinates (u, v) of bearings (any shapes that broadcast)."""
        image_angle = self.zero_angle + _sign(self.direction) * np.asarray(
            azimuth, dtype=np.float64
        )
        r = self.elevation_to_radius(elevation)
        return self.centre[0] + r * np.cos(image_angle), self.centre[1] - r * np.sin(image_angle)

    def annulus_mask(self) -> NDArray[np.bool_]:
        """Boolean mask (height, width) of the pixels between the inner and outer radius."""
        v, u = np.mgrid[0 : self.height, 0 : self.width]
        r = np.hypot(u - self.centre[0], v - self.centre[1])
        return (r >= self.inner_radius) & (r <= self.outer_radius)

    def horizon_side(self, u: ArrayLike, v: ArrayLike, tolerance: float = 0.0) -> NDArray[np.int8]:
        """Seed 001's gamma_IO (eq. 8): +1 above the horizon, -1 below, 0 within ``tolerance`` px.

        "Above" means elevation > 0 whichever side of the circle the mirror images it on.
        """
        du = np.asarray(u, dtype=np.float64) - self.centre[0]
        dv = np.asarray(v, dtype=np.float64) - self.centre[1]
        offset = np.hypot(du, dv) - self.horizon_radius
        side = np.sign(offset) * (1.0 if self.up_is_outside else -1.0)
        return np.where(np.abs(offset) <= tolerance, 0, side).astype(np.int8)


def _interp_linear_extrapolate(x: FloatArray, xp: FloatArray, fp: FloatArray) -> FloatArray:
    """``np.interp`` with linear extrapolation beyond both ends (xp increasing)."""
    y = np.interp(x, xp, fp)
    lo_slope = (fp[1] - fp[0]) / (xp[1] - xp[0])
    hi_slope = (fp[-1] - fp[-2]) / (xp[-1] - xp[-2])
    y = np.where(x < xp[0], fp[0] + (x - xp[0]) * lo_slope, y)
    return np.where(x > xp[-1], fp[-1] + (x - xp[-1]) * hi_slope, y)
