"""Seed 001, section 2: the movement (rho, psi, alpha) from landmark triples, and its estimate.

Model (seed 001, eq. 1-4; the same one as :mod:`homebench.methods.warping.method`): the robot left
the
goal H in direction ``alpha`` (goal robot frame, ccw) for a distance ``d`` and turned by ``psi``
(ccw heading change, goal -> current). A landmark at distance ``r`` from H seen at azimuth
``theta`` from H and ``theta'`` from C satisfies (eq. 2, ``rho = d / r``)::

    sin(psi + theta' - theta) = rho * sin(psi + theta' - alpha)

It is the cross product of ``L - C`` with the current ray's world direction ``phi = theta' + psi``
(goal frame): ``r sin(phi - theta) = d sin(phi - alpha)``, so it holds for ccw azimuths as
geometry.py defines them (and for cw ones too: the equation is odd in every angle). H lies at
``alpha + pi`` from C in the goal frame, hence at ``beta = pi + alpha - psi`` in the current robot
frame (eq. 4 and 7).

**Closed form of eq. 3** (three landmarks, one rho). For fixed psi the equations are linear in
``(a, b) = (rho cos alpha, rho sin alpha)``: ``a sin(phi_i) - b cos(phi_i) = sin(psi + delta_i)``
with ``delta_i = theta'_i - theta_i``. Three equations in two unknowns are consistent exactly when
the 3 x 3 determinant vanishes; expanded along the right-hand side it is
``sum_i w_i sin(psi + delta_i) = 0`` with ``w_i = sin(theta'_k - theta'_j)`` over cyclic
(i, j, k), since ``phi_k - phi_j`` does not depend on psi. So
``P sin(psi) + Q cos(psi) = 0`` with ``P = sum w_i cos(delta_i)``, ``Q = sum w_i sin(delta_i)``:
two roots, ``psi0 = atan2(-Q, P)`` and ``psi0 + pi``, which share one (a, b) (both sides flip
sign) and so one rho and alpha, but give home directions ``beta`` half a turn apart.

**Which root** (a reading: eq. 3 does not choose): the one that puts the landmarks *ahead* on
the current rays. Landmark i lies at ``s_i / r = cos(psi + delta_i) - rho cos(phi_i - alpha)``
along its ray from C, and the other root flips every ``s_i``; the root with the larger
``sum s_i`` is taken. True bearings put every landmark ahead (``s_i > 0``) on the true root.

**Triples discarded** (``valid`` False): when psi is undetermined (``P = Q = 0``), or (a, b) is
undetermined (all three current bearings on one line through C) — eq. 3 then has no unique real
solution. With ``ahead_filter`` (a departure, off by default: the paper keeps every triple eq. 3
solves) also the triples where, on the chosen root, some landmark would lie behind C on its ray
(``s_i <= 0``): true bearings never do that, noisy or mismatched ones often do.

**No direction at rho = 0** (a reading): eq. 3 with ``rho = 0`` holds for every alpha, so such a
triple gives psi but no alpha; identical views (every triple at rho = 0) give a turn and no
home direction rather than the arbitrary ``alpha = atan2(0, 0)``. A triple counts as rho = 0
below ``DEGENERATE``.

**Triples**: all ``C(n, 3)`` of them when ``max_triples`` is None or at least ``C(n, 3)``,
else ``max_triples`` drawn uniformly (with replacement) by a generator seeded by ``seed`` and a
checksum of the bearings themselves, so one pair of views always gives the same answer. All
triples are solved in chunks of ``CHUNK`` to bound memory.

**Estimate** (eq. 5-7): alpha-hat and psi-hat each minimise the circular sum of squared
deviations over the valid triples (alpha over those with rho > 0). The minimiser is found
exactly (see :func:`circular_least_squares`) instead of by a search over ``alpha-bar`` on a grid
(eq. 5 names no grid step: the exact minimiser is the limit of a finer and finer grid).
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from math import comb

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import TWO_PI, wrap_angle, wrap_positive

FloatArray = NDArray[np.float64]
IndexArray = NDArray[np.intp]

#: Below this, ``hypot(P, Q)``, the normal matrix's determinant or rho counts as zero.
DEGENERATE = 1e-12
#: Triples solved at once when all of them are solved (memory: about 200 bytes per triple).
CHUNK = 1 << 18


@dataclass(frozen=True)
class TripleSolutions:
    """Per-triple solutions of eq. 3; every array has shape (t,). ``alpha`` is meaningless
    where ``rho`` is 0 (see :attr:`has_direction`)."""

    rho: FloatArray
    psi: FloatArray
    alpha: FloatArray
    valid: NDArray[np.bool_]

    @property
    def has_direction(self) -> NDArray[np.bool_]:
        """Valid triples with rho > 0, whose alpha is determined."""
        return self.valid & (self.rho > DEGENERATE)


def solve_triples(
    theta_goal: FloatArray,
    theta_current: FloatArray,
    triples: IndexArray,
    *,
    ahead_filter: bool = False,
) -> TripleSolutions:
    """Solve eq. 3 for many landmark triples at once.

    ``theta_goal`` and ``theta_current``: azimuths (radians, ccw) of n matched landmarks seen
    from the goal and from the current place, shape (n,); ``triples``: landmark indices, shape
    (t, 3). Returns ``rho`` >= 0, ``psi`` and ``alpha`` in [-pi, pi), and ``valid`` (see the
    module docstring for what is discarded; ``ahead_filter`` discards more). Sines and cosines
    are taken once per landmark; per triple everything follows by angle-addition products.
    """
    theta_p = np.asarray(theta_current, dtype=np.float64)
    delta = theta_p - np.asarray(theta_goal, dtype=np.float64)
    index = np.asarray(triples, dtype=np.intp).T  # (3, t): rows are contiguous
    sp, cp = np.sin(theta_p)[index], np.cos(theta_p)[index]
    sd, cd = np.sin(delta)[index], np.cos(delta)[index]
    j, k = [1, 2, 0], [2, 0, 1]
    w = sp[k] * cp[j] - cp[k] * sp[j]  # sin(theta'_k - theta'_j), (i, j, k) cyclic
    p = np.sum(w * cd, axis=0)
    q = np.sum(w * sd, axis=0)
    norm = np.hypot(p, q)
    safe_norm = np.where(norm > DEGENERATE, norm, 1.0)
    sin_psi, cos_psi = -q / safe_norm, p / safe_norm  # psi0 = atan2(-Q, P)

    sin_phi = sp * cos_psi + cp * sin_psi  # phi = theta' + psi0
    cos_phi = cp * cos_psi - sp * sin_psi
    rhs = sin_psi * cd + cos_psi * sd  # sin(psi0 + delta)
    # Normal equations of the (consistent) 3 x 2 system [sin phi, -cos phi] (a, b) = rhs; their
    # determinant is sum_i w_i**2 (Lagrange's identity), zero when all rays lie on one line.
    m11 = np.sum(sin_phi**2, axis=0)
    m22 = np.sum(cos_phi**2, axis=0)
    m12 = -np.sum(sin_phi * cos_phi, axis=0)
    r1 = np.sum(sin_phi * rhs, axis=0)
    r2 = -np.sum(cos_phi * rhs, axis=0)
    det = np.sum(w**2, axis=0)
    safe_det = np.where(det > DEGENERATE, det, 1.0)
    a = (m22 * r1 - m12 * r2) / safe_det
    b = (m11 * r2 - m12 * r1) / safe_det

    ahead = (cos_psi * cd - sin_psi * sd) - (a * cos_phi + b * sin_phi)  # s_i / r
    flip = np.sum(ahead, axis=0) < 0.0
    psi = wrap_angle(np.arctan2(sin_psi, cos_psi) + np.where(flip, np.pi, 0.0))
    valid = (norm > DEGENERATE) & (det > DEGENERATE)
    if ahead_filter:
        valid &= np.all(np.where(flip, -ahead, ahead) > 0.0, axis=0)
    return TripleSolutions(
        rho=np.hypot(a, b), psi=psi, alpha=wrap_angle(np.arctan2(b, a)), valid=valid
    )


def all_triples(n: int) -> IndexArray:
    """All ``C(n, 3)`` index triples (i < j < k) in lexicographic order, shape (C(n, 3), 3)."""
    if n < 3:
        return np.empty((0, 3), dtype=np.intp)
    j, k = np.triu_indices(n, 1)  # pairs j < k, lexicographic
    start = np.searchsorted(j, np.arange(n - 2), side="right")  # first pair with j > i
    blocks = [
        np.column_stack([np.full(len(j) - first, i), j[first:], k[first:]])
        for i, first in enumerate(start)
    ]
    return np.concatenate(blocks).astype(np.intp)


def choose_triples(n: int, max_triples: int | None, rng: np.random.Generator) -> IndexArray:
    """Landmark triples to solve, shape (t, 3), each of three distinct indices in [0, n).

    All ``C(n, 3)`` triples (in lexicographic order) when ``max_triples`` is None or at least
    ``C(n, 3)``; otherwise ``max_triples`` triples drawn uniformly with replacement from ``rng``.
    """
    if n < 3:
        return np.empty((0, 3), dtype=np.intp)
    if max_triples is None or comb(n, 3) <= max_triples:
        return all_triples(n)
    i = rng.integers(0, n, max_triples)
    j = rng.integers(0, n - 1, max_triples)
    j += j >= i
    low, high = np.minimum(i, j), np.maximum(i, j)
    k = rng.integers(0, n - 2, max_triples)
    k += k >= low
    k += k >= high
    return np.stack([i, j, k], axis=1).astype(np.intp)


def circular_least_squares(angles: FloatArray) -> tuple[float, float]:
    """Exact minimiser of eq. 5: ``argmin_m sum_i diff(angles_i - m)**2`` with eq. 6's ``diff``.

    ``angles``: shape (n,), n >= 1. Returns ``(m, ssd)``, m in [-pi, pi).

    With the angles sorted in [0, 2*pi), cut k (k = 0..n-1) unwraps them onto one line by adding
    2*pi to the first k. At the true minimiser m* every wrapped deviation is the plain deviation
    of one such unwrapping (the one cut at m* + pi), whose variance is therefore <= f(m*); and at
    the mean of any unwrapping, f is <= that unwrapping's variance (wrapped deviations are never
    longer). So the mean of the unwrapping with the least variance is a global minimiser, and
    that variance is the minimum. All n variances come from prefix sums: O(n log n).
    """
    x = np.sort(wrap_positive(angles))
    n = x.size
    k = np.arange(n)
    head = np.concatenate([[0.0], np.cumsum(x)[:-1]])  # sum of the first k angles
    total = x.sum() + TWO_PI * k
    total_sq = np.sum(x**2) + 2.0 * TWO_PI * head + TWO_PI**2 * k
    variance = total_sq - total**2 / n
    best = int(np.argmin(variance))
    return float(wrap_angle(total[best] / n)), float(max(variance[best], 0.0))


@dataclass(frozen=True)
class Movement:
    """The estimated movement from goal to current (eq. 5-7) and what it rests on.

    ``alpha``: direction of the movement in the goal robot frame, None when no valid triple has
    rho > 0 (no displacement seen); ``psi``: heading change, goal -> current; both radians, ccw,
    in [-pi, pi). ``alpha_rms``: root mean square circular deviation of the triples' alphas from
    ``alpha`` (radians, None without alpha); ``rho_median``: median of the valid triples' rho =
    d / r; ``n_direction``: valid triples with rho > 0.
    """

    alpha: float | None
    psi: float
    alpha_rms: float | None
    rho_median: float
    n_triples: int
    n_valid: int
    n_direction: int

    @property
    def home_direction(self) -> float | None:
        """``beta = pi + alpha - psi`` (eq. 7): home in the current robot frame, radians, ccw;
        None without alpha."""
        if self.alpha is None:
            return None
        return float(wrap_angle(np.pi + self.alpha - self.psi))


def _solve_chunks(
    theta: FloatArray, theta_p: FloatArray, triples: IndexArray, ahead_filter: bool
) -> TripleSolutions:
    """:func:`solve_triples` on ``triples`` in chunks of ``CHUNK`` rows, concatenated."""
    parts = [
        solve_triples(theta, theta_p, triples[start : start + CHUNK], ahead_filter=ahead_filter)
        for start in range(0, max(len(triples), 1), CHUNK)
    ]
    names = ("rho", "psi", "alpha", "valid")
    return TripleSolutions(**{n: np.concatenate([getattr(p, n) for p in parts]) for n in names})


def estimate_movement(
    theta_goal: FloatArray,
    theta_current: FloatArray,
    max_triples: int | None,
    seed: int,
    *,
    ahead_filter: bool = False,
) -> Movement | None:
    """Eq. 3 on the triples of n matched landmarks, then eq. 5-7.

    ``theta_goal``, ``theta_current``: azimuths (n,) of the matched landmarks from the goal and
    the current place, radians, ccw. ``max_triples``: see :func:`choose_triples`. None when no
    triple has a real solution (or n < 3).
    """
    theta = np.ascontiguousarray(theta_goal, dtype=np.float64)
    theta_p = np.ascontiguousarray(theta_current, dtype=np.float64)
    rng = np.random.default_rng([seed, zlib.crc32(theta.tobytes() + theta_p.tobytes())])
    triples = choose_triples(len(theta), max_triples, rng)
    solutions = _solve_chunks(theta, theta_p, triples, ahead_filter)
    valid, direction = solutions.valid, solutions.has_direction
    n_valid, n_direction = int(valid.sum()), int(direction.sum())
    if n_valid == 0:
        return None
    psi, _ = circular_least_squares(solutions.psi[valid])
    alpha, alpha_rms = None, None
    if n_direction:
        alpha, alpha_ssd = circular_least_squares(solutions.alpha[direction])
        alpha_rms = float(np.sqrt(alpha_ssd / n_direction))
    return Movement(
        alpha=alpha,
        psi=psi,
        alpha_rms=alpha_rms,
        rho_median=float(np.median(solutions.rho[valid])),
        n_triples=len(triples),
        n_valid=n_valid,
        n_direction=n_direction,
    )
