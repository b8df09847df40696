"""The sector control law of seed 000 (section 2.1) and its pose correction, on bearing angles.

Inputs are bearings (azimuths, radians, ccw, 0 = heading; geometry.py's convention) of the same
n features in the current view S and the goal view G: two arrays of shape (n,), row k of both
being feature k.

- **Bearings** (eq. 1): ``S_i = 2*pi*x_i / width``, via
  :meth:`homebench.geometry.PanoramaGeometry.column_to_azimuth` (which also honours the zero
  column and direction of a panorama).
- **Ordering filter**: features whose retinotopic order differs between S and G are dropped;
  the kept ones are a longest common subsequence of the two orders. A panorama's order is
  circular and the paper does not say where its sequences start; the default reading
  (``circular``) cuts the first order anywhere and tries every rotation of the second, the
  option ``linear`` reads both from their smallest position (column 0 when given columns). The
  features are the same in both views, so each LCS is a longest increasing subsequence of
  positions (O(n log n)); all rotations cost O(n^2 log n), their lengths found in a compiled
  loop (:mod:`~homebench.methods.klt_sector.sector_law_kernels`, numba, integers: 4.5 ms in Python
  ->
  0.35 ms for 100 features), the chain of the first longest rotation by
  :func:`longest_increasing`.
- **Sectors**: consecutive kept features in the circular order of S bound n sectors (the last
  one wraps round to the first feature); sector k has angular size ``S_k`` in S and ``G_k`` in G
  (ccw from its first to its second feature, in [0, 2*pi)).
- **Sector vectors** (the paper's reading, section 2.1): "If the difference is positive, we
  define a vector parallel to the bisector of this sector with a magnitude proportional to
  |G_k - S_k|. If the difference is negative, then the vector has opposite direction ...
  targeted towards the direction of the motion that is required in order to equalize the
  angular extent of the sector". Moving along a sector's bisector makes the sector grow (its
  two features spread apart as the robot approaches them, or, for a sector wider than pi, the
  complementary sector behind shrinks), so a sector that is larger at the goal (G_k > S_k)
  pulls along its bisector and one that is smaller pushes the other way:
  ``v_k = (G_k - S_k) * (cos b_k, sin b_k)`` and ``M = sum_k v_k``. The bisector ``b_k`` is
  the sector's middle in the current view (``bisectors="current"``, the default: the robot
  acts on what it sees and needs no compass), or its middle in the goal view turned into the
  current frame by the estimated heading change (``"goal"``). ``M`` is in the current robot
  frame; its length (radians) falls to zero at the goal.
- **Pose correction** (section 2.3): at one place, panoramas taken with different headings are
  shifted copies; the heading change is the median of the features' angular shifts.
"""

from __future__ import annotations

import bisect
from collections.abc import Hashable, Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.geometry import TWO_PI, PanoramaGeometry, angle_diff, circular_mean, wrap_angle

FloatArray = NDArray[np.float64]
BisectorFrame = Literal["current", "goal"]
LcsOrder = Literal["circular", "linear"]

#: Fewest features the law needs (two independent sectors).
MIN_FEATURES = 3


def bearings(columns: ArrayLike, geometry: PanoramaGeometry) -> FloatArray:
    """Bearing angles (eq. 1) of (fractional) panorama ``columns`` (any shape), radians."""
    return geometry.column_to_azimuth(columns)


def longest_increasing(values: Sequence[int]) -> list[int]:
    """Indices of a longest strictly increasing subsequence of ``values`` (patience sorting)."""
    tails: list[int] = []  # smallest tail value of an increasing run of each length
    tail_index: list[int] = []
    previous = [-1] * len(values)
    for i, value in enumerate(values):
        k = bisect.bisect_left(tails, value)
        if k == len(tails):
            tails.append(value)
            tail_index.append(i)
        else:
            tails[k] = value
            tail_index[k] = i
        previous[i] = tail_index[k - 1] if k else -1
    chain: list[int] = []
    i = tail_index[-1] if tail_index else -1
    while i >= 0:
        chain.append(i)
        i = previous[i]
    return chain[::-1]


def longest_common_order(
    first: Sequence[Hashable], second: Sequence[Hashable], circular: bool = True
) -> list[Hashable]:
    """A longest common subsequence of two orders of distinct items, circular (``second`` may
    start anywhere; ``first``'s start is arbitrary too, as its rotations give the same LCS
    lengths) or linear.

    Items in only one order are ignored. Returns the kept items in ``first``'s order (starting
    where ``first`` starts).
    """
    position = {item: i for i, item in enumerate(first)}
    common = [item for item in second if item in position]
    if not common:
        return []
    positions = np.array([position[item] for item in common], dtype=np.int64)
    start = 0
    if circular:  # numba is imported by the first circular filter, not with this module
        from homebench.methods.klt_sector.sector_law_kernels import first_longest_rotation

        start = int(first_longest_rotation(positions))
    rotated = common[start:] + common[:start]
    chain = longest_increasing(np.roll(positions, -start).tolist())
    return sorted((rotated[i] for i in chain), key=position.__getitem__)


def order_filter(current: ArrayLike, goal: ArrayLike, circular: bool = True) -> NDArray[np.bool_]:
    """Mask (n,) of the features kept by the ordering filter.

    ``current``, ``goal``: positions of the n features along each view's order, bearings or
    panorama columns, shape (n,); ``circular``: see the module docstring.
    """
    s = np.asarray(current, dtype=np.float64)
    g = np.asarray(goal, dtype=np.float64)
    order_s = np.argsort(s, kind="stable").tolist()
    order_g = np.argsort(g, kind="stable").tolist()
    kept = longest_common_order(order_s, order_g, circular)
    mask = np.zeros(s.shape, dtype=bool)
    mask[np.asarray(kept, dtype=np.intp)] = True
    return mask


def heading_change(current: ArrayLike, goal: ArrayLike) -> float:
    """Heading change goal -> current (radians, ccw, in [-pi, pi)): the median angular shift.

    A robot that turned ccw by psi sees a feature at ``goal - psi``, so each feature suggests
    ``psi = wrap(goal - current)``; the median is taken around their circular mean so that
    shifts near +-pi do not split. NaN for no features.
    """
    shifts = angle_diff(goal, current).ravel()
    if shifts.size == 0:
        return float("nan")
    centre = circular_mean(shifts)
    return float(wrap_angle(centre + np.median(angle_diff(shifts, centre))))


def sector_vectors(
    current: ArrayLike, goal: ArrayLike, bisectors: BisectorFrame = "current"
) -> FloatArray:
    """Vectors (n, 2) of the n sectors between consecutive features (current circular order).

    Features must be in the same circular order in both views (see :func:`order_filter`).
    With ``bisectors="goal"`` the bisectors are the goal view's, turned into the current frame
    by :func:`heading_change`.
    """
    s = np.asarray(current, dtype=np.float64)
    g = np.asarray(goal, dtype=np.float64)
    order = np.argsort(s, kind="stable")
    s, g = s[order], g[order]
    size_s = (np.roll(s, -1) - s) % TWO_PI
    size_g = (np.roll(g, -1) - g) % TWO_PI
    if bisectors == "current":
        middle = s + size_s / 2.0
    elif bisectors == "goal":
        middle = g + size_g / 2.0 - heading_change(s, g)
    else:
        raise ValueError(f"bisectors must be 'current' or 'goal', got {bisectors!r}")
    change = size_g - size_s
    return np.stack([change * np.cos(middle), change * np.sin(middle)], axis=-1)


def motion_vector(
    current: ArrayLike, goal: ArrayLike, bisectors: BisectorFrame = "current"
) -> FloatArray:
    """M (shape (2,), current robot frame, radians): the sum of :func:`sector_vectors`."""
    return sector_vectors(current, goal, bisectors).sum(axis=0)


def goal_reached(motion: ArrayLike, threshold: float) -> bool:
    """The paper's stop test: ``|M|`` (shape (2,)) below ``threshold`` (radians)."""
    return bool(np.hypot(*np.asarray(motion, dtype=np.float64)) < threshold)
