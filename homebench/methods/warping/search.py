"""The 1-D warping search (seed 001): every (rho, alpha, psi) hypothesis, fast and exact.

Notation: n columns; goal signal g and current signal c, shape (n,); alpha a whole number
``m = a * s`` of columns (``s = n / n_alpha``), psi ``p * t`` columns (``t = n / n_psi``). The goal
warped by (rho[r], alpha) samples g at ``m + P[r, (k - m) % n]`` (P: :func:`warp_positions`) and
is compared with the current signal turned by psi, ``c[(k - p t) % n]``. With ``j = k - m``:

    cost(r, a, p) = sum_j distance(Q[j, r, a], c[(j + u) % n]),    u = (m - p t) mod n,
    Q[j, r, a] = g[(low[r, j] + m) % n] + frac[r, j] * dg[(low[r, j] + m) % n],

``dg[i] = g[(i + 1) % n] - g[i]`` (linear interpolation). Q's row j for rho r is row
``low[r, j]`` of the goal's (n, n_alpha) table of shifts, so Q is built by copying whole rows,
and the cross terms of all hypotheses are one matrix product (turned currents) x Q, with the
turns u the multiples of gcd(s, t) (pairs (u, alpha) that are no psi of the grid are masked).
With the squared difference the energy of each Q column joins the product as one more row.

:func:`exact_costs` evaluates hypotheses one by one in float64: the reference, and the cost the
method reports. :func:`search_many` screens every hypothesis with that matrix product in float32,
then re-scores with :func:`exact_costs` every hypothesis whose screened score lies within a bound on
the float32 rounding error of the best one; the smallest exact cost wins, ties going to the
lowest ``(r, a, p)`` (as ``np.argmin`` over the cost array). The result is the exact argmin of
:func:`exact_costs`, whatever BLAS kernel, SIMD width or thread count computed the screen; the
float64 costs are row sums in numpy's fixed pairwise order. In practice one or two hypotheses
are re-scored; the alphas of rho = 0 (one identity warp) tie exactly and count as alpha = 0.
It screens a few current signals of one goal by one matrix product (a block of turned
currents, one Q): since each answer is the exact argmin, it does not depend on which currents
share a block, and a block's product costs about a fifth less per current than a current's own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import TWO_PI

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

#: Unit roundoff of float32.
_U32 = 2.0**-24
#: Column norms of the centred signals the float32 screen takes: above the lower bound their
#: squares are normal floats, below the upper bound no product or sum overflows.
SCREEN_RANGE = (1e-12, 1e15)


def warp_positions(n_columns: int, rho: tuple[float, ...]) -> FloatArray:
    """Where the warped goal signal samples the goal, for alpha = 0: shape (n_rho, n_columns).

    Entry ``[r, j]`` is the goal column (real, in ``[0, n_columns]``) seen at canonical column
    j (azimuth ``phi = 2*pi*j/n``) for ``rho[r]``: ``theta * n / (2*pi)`` with
    ``theta = phi - arcsin(rho * sin phi)``, written ``j - arcsin(...) * n / (2*pi)`` so that
    ``rho = 0`` gives exactly j. Alpha of m whole columns is the same warp turned by m columns:
    position ``m + positions[r, (j - m) % n]``.
    """
    phi = TWO_PI * np.arange(n_columns) / n_columns
    arc = np.arcsin(np.asarray(rho)[:, None] * np.sin(phi[None, :]))
    return (np.arange(n_columns)[None, :] - arc * (n_columns / TWO_PI)) % n_columns


def interpolation(positions: FloatArray, n_columns: int) -> tuple[IntArray, FloatArray]:
    """``(low, frac)`` of ``positions`` (any shape, columns in ``[0, n_columns]``): a periodic
    signal s at a position is ``s[low] + frac * (s[(low + 1) % n] - s[low])``."""
    low = np.floor(positions)
    return low.astype(np.intp) % n_columns, positions - low


@lru_cache(maxsize=8)
def warp_tables(
    n_columns: int, rho: tuple[float, ...], n_alpha: int
) -> tuple[IntArray, FloatArray]:
    """Linear-interpolation tables of the warped goal signal (``n_alpha`` must divide
    ``n_columns``: alpha in whole columns).

    Returns ``(low, frac)``, each of shape (n_rho * n_alpha, n_columns): the warped signal at
    canonical column k (azimuth ``phi = 2*pi*k/n``) for ``(rho[r], alpha[a])`` (row
    ``r * n_alpha + a``) is ``(1 - frac) * goal[low] + frac * goal[(low + 1) % n]``; rows of
    rho = 0 are exactly the identity (``low = k``, ``frac = 0``).
    """
    n = n_columns
    shift = (n // n_alpha) * np.arange(n_alpha)[:, None]  # (n_alpha, 1) columns
    base = warp_positions(n, rho)  # (n_rho, n)
    positions = (shift + base[:, (np.arange(n)[None, :] - shift) % n]) % n
    return interpolation(positions.reshape(len(rho) * n_alpha, n), n)


@dataclass(frozen=True)
class SearchGrid:
    """Index tables of one search grid (n columns, n_rho x n_alpha x n_psi hypotheses).

    ``low``, ``frac`` (n_rho * n_alpha, n): :func:`warp_tables`; ``low_t`` (n, n_rho) and
    ``frac_t`` (n, n_rho, n_alpha) float32: :func:`interpolation` of :func:`warp_positions`,
    transposed (``frac_t`` repeated along alpha), for the screen; ``goal_shifts``
    (n + 1, n_alpha): ``(i + a s) % n``;
    ``current_shifts`` (n_u, n + 1): ``(j + v * unit) % n`` and a last column n (the screen's
    energy coefficient), the turns ``u = v * unit`` of the current signal the screen tries
    (``unit = gcd(s, t)``); ``invalid`` (n_u, n_rho * n_alpha) or None: the (u, alpha) pairs
    that are no psi of the grid (only when s is not a multiple of t); ``high``: ``(low + 1) %
    n``; ``turned_columns`` (n_psi, n): ``(k - p t) % n``, the current signal
    turned by each psi; ``identity`` (n_rho,): rho = 0, the warp that is the identity for
    every alpha.
    """

    n_columns: int
    n_rho: int
    n_alpha: int
    n_psi: int
    low: IntArray
    frac: FloatArray
    low_t: IntArray
    frac_t: NDArray[np.float32]
    goal_shifts: IntArray
    current_shifts: IntArray
    unit: int
    invalid: NDArray[np.bool_] | None
    high: IntArray
    turned_columns: IntArray
    identity: NDArray[np.bool_]

    @property
    def alpha_step(self) -> int:
        """s: columns per alpha step."""
        return self.n_columns // self.n_alpha

    @property
    def psi_step(self) -> int:
        """t: columns per psi step."""
        return self.n_columns // self.n_psi


@lru_cache(maxsize=8)
def search_grid(n_columns: int, rho: tuple[float, ...], n_alpha: int, n_psi: int) -> SearchGrid:
    """The tables of a grid; ``n_alpha`` and ``n_psi`` must divide ``n_columns``."""
    n, n_rho = n_columns, len(rho)
    s, t = n // n_alpha, n // n_psi
    unit = math.gcd(s, t)
    base_low, base_frac = interpolation(warp_positions(n, rho), n)
    low, frac = warp_tables(n, rho, n_alpha)
    turns = unit * np.arange(n // unit)
    current_shifts = np.full((len(turns), n + 1), n)
    current_shifts[:, :n] = (np.arange(n)[None, :] + turns[:, None]) % n
    invalid = (s * np.arange(n_alpha)[None, :] - turns[:, None]) % t != 0  # (n_u, n_alpha)
    return SearchGrid(
        n_columns=n,
        n_rho=n_rho,
        n_alpha=n_alpha,
        n_psi=n_psi,
        low=low,
        frac=frac,
        low_t=np.ascontiguousarray(base_low.T),
        frac_t=np.repeat(base_frac.T.astype(np.float32)[:, :, None], n_alpha, axis=2),
        goal_shifts=(np.arange(n + 1)[:, None] + s * np.arange(n_alpha)[None, :]) % n,
        current_shifts=current_shifts,
        unit=unit,
        invalid=np.tile(invalid, (1, n_rho)) if invalid.any() else None,
        high=(low + 1) % n,
        turned_columns=(np.arange(n)[None, :] - t * np.arange(n_psi)[:, None]) % n,
        identity=np.asarray(rho) == 0.0,
    )


def warped_goal(grid: SearchGrid, goal: FloatArray, rows: IntArray) -> FloatArray:
    """The goal (n,) warped for the (rho, alpha) of ``rows`` (``r * n_alpha + a``, shape (K,)):
    shape (K, n), float64, :func:`warp_tables` read as ``g[low] + frac * (g[high] - g[low])``."""
    below = goal[grid.low[rows]]
    return below + grid.frac[rows] * (goal[grid.high[rows]] - below)


def _distance(warped: FloatArray, turned: FloatArray, ssd: bool) -> FloatArray:
    """Sum over the last axis (numpy's fixed pairwise order along each row) of the squared
    differences, or minus the products (arrays broadcasting to (..., n))."""
    if ssd:
        return np.sum((warped - turned) ** 2, axis=-1)
    return -np.sum(warped * turned, axis=-1)


def exact_costs(
    grid: SearchGrid,
    currents: FloatArray,
    goal: FloatArray,
    hypotheses: tuple[IntArray, IntArray, IntArray, IntArray],
    ssd: bool,
) -> FloatArray:
    """Float64 costs of the hypotheses ``(pair, r, a, p)`` (four int arrays of shape (K,)):
    ``(r, a, p)`` for the current signal ``currents[pair]`` (``currents``: (m, n)), shape (K,):
    the sum over canonical columns k of the squared differences (``ssd``) or minus the
    products of the warped goal (:func:`warped_goal`) and the turned current signal (both
    (n,)). Summed in k order, so that the hypotheses of rho = 0 (the same identity warp for
    every alpha) tie exactly."""
    pair, r, a, p = hypotheses
    warped = warped_goal(grid, goal, r * grid.n_alpha + a)
    return _distance(warped, currents[pair[:, None], grid.turned_columns[p]], ssd)


def all_costs(grid: SearchGrid, current: FloatArray, goal: FloatArray, ssd: bool) -> FloatArray:
    """:func:`exact_costs` of every hypothesis, shape (n_rho, n_alpha, n_psi): the same
    arithmetic, one rho at a time."""
    turned = current[grid.turned_columns][None, :, :]  # (1, n_psi, n)
    alphas = np.arange(grid.n_alpha)
    return np.stack(
        [
            _distance(warped_goal(grid, goal, r * grid.n_alpha + alphas)[:, None, :], turned, ssd)
            for r in range(grid.n_rho)
        ]
    )


@dataclass(frozen=True)
class GoalScreen:
    """The goal's part of the float32 screen: ``warped`` (n + 1, n_rho * n_alpha) float32, rows
    0..n-1 the matrix Q of the module docstring, row n each column's energy (sum of squares);
    ``centre``: the grey level subtracted from both signals; ``big``: the largest
    |goal - centre|; ``norm``: the largest column norm of Q."""

    warped: NDArray[np.float32]
    centre: float
    big: float
    norm: float


def screen_goal(grid: SearchGrid, goal: FloatArray, ssd: bool) -> GoalScreen:
    """The goal's part of the screen (``ssd``: centre the signals, which changes no squared
    difference and shrinks the float32 error)."""
    n, n_rho, n_alpha = grid.n_columns, grid.n_rho, grid.n_alpha
    centre = float(np.add.reduce(goal)) / n if ssd else 0.0
    with np.errstate(over="ignore", invalid="ignore"):  # search_many() checks the scale
        g = (goal - centre).astype(np.float32)
    shifted = g[grid.goal_shifts]  # (n + 1, n_alpha): g turned by each alpha
    q = np.empty((n + 1, n_rho, n_alpha), np.float32)
    np.take(shifted, grid.low_t, axis=0, out=q[:n], mode="clip")
    slope = np.take(shifted[1:] - shifted[:-1], grid.low_t, axis=0)
    slope *= grid.frac_t
    q[:n] += slope
    warped = q.reshape(n + 1, n_rho * n_alpha)
    with np.errstate(over="ignore", invalid="ignore"):
        np.einsum("jh,jh->h", warped[:n], warped[:n], out=warped[n])
    norm = math.sqrt(float(warped[n].max()) * (1.0 + 1e-3))
    return GoalScreen(warped, centre, float(np.abs(g).max()), norm)


#: Bytes of float32 scores screened by one matrix product (a few current views of one goal at
#: a time: one product per block shares the goal's part, and the block stays in the caches).
SCREEN_BLOCK_BYTES = 2 << 20

#: The best hypothesis ``(r, a, p)`` of a search and its exact cost.
Best = tuple[tuple[int, int, int], float]


def search_many(
    grid: SearchGrid, currents: FloatArray, goal: FloatArray, screen: GoalScreen, ssd: bool
) -> list[Best]:
    """The best hypothesis ``(r, a, p)`` and its exact cost for each current signal of
    ``currents`` (K, n) towards ``goal`` (n,): the argmin of :func:`all_costs` (lowest index
    among equal costs), found through the float32 screen (module docstring), the screen of a
    block of currents (:data:`SCREEN_BLOCK_BYTES`) one matrix product; ``screen``:
    :func:`screen_goal` of ``goal``. Signals whose scale float32 cannot hold (beyond
    :data:`SCREEN_RANGE`, or not finite) are searched by :func:`all_costs` itself."""
    centred = currents - screen.centre
    norms = np.sqrt(np.einsum("kn,kn->k", centred, centred) * (1.0 + 1e-3))  # (K,)
    low, high = SCREEN_RANGE
    fits = (low < screen.norm < high) & (norms < high)  # (K,); False for NaN
    block = max(1, SCREEN_BLOCK_BYTES // (4 * screen.warped.shape[1] * len(grid.current_shifts)))
    found: list[Best] = []
    for start in range(0, len(currents), block):
        part = slice(start, start + block)
        if fits[part].all():
            found += _screened(grid, currents[part], centred[part], norms[part], goal, screen, ssd)
            continue
        for k in range(start, min(start + block, len(currents))):  # rare: one by one
            if fits[k]:
                one = slice(k, k + 1)
                found += _screened(grid, currents[one], centred[one], norms[one], goal, screen, ssd)
            else:
                found.append(_searched(grid, currents[k], goal, ssd))
    return found


def _searched(grid: SearchGrid, current: FloatArray, goal: FloatArray, ssd: bool) -> Best:
    """The argmin of :func:`all_costs` itself (signals the float32 screen cannot hold)."""
    cost = all_costs(grid, current, goal, ssd)
    r, a, p = (int(i) for i in np.unravel_index(int(np.argmin(cost)), cost.shape))
    return (r, a, p), float(cost[r, a, p])


def _screened(
    grid: SearchGrid,
    currents: FloatArray,
    centred: FloatArray,
    norms: FloatArray,
    goal: FloatArray,
    screen: GoalScreen,
    ssd: bool,
) -> list[Best]:
    """:func:`search_many` of ``currents`` (K, n; ``centred``: minus the screen's centre,
    ``norms`` (K,): their norms with a margin) through one float32 screen."""
    n, k = grid.n_columns, len(currents)
    c = np.empty((k, n + 1), np.float32)
    c[:, :n] = centred
    c[:, n] = -0.5 if ssd else 0.0
    # score (higher is better): cross - energy / 2 = (|c|^2 - ssd) / 2, or the scalar product
    shifts = grid.current_shifts  # (n_u, n + 1)
    score = (c[:, shifts].reshape(-1, n + 1) @ screen.warped).reshape(k, len(shifts), -1)
    if grid.invalid is not None:
        np.copyto(score, -np.inf, where=grid.invalid)
    row_best = score.max(axis=2)  # (K, n_u)
    peaks = zip(row_best.max(axis=1).tolist(), norms.tolist(), strict=True)
    low = np.array([top - 3.0 * _tolerance(n, norm, screen) for top, norm in peaks])  # float64
    pair, v = np.nonzero(row_best >= low[:, None])  # the rows that hold candidates
    hit, column = np.nonzero(score[pair, v] >= low[pair, None])
    pair, v = pair[hit], v[hit]
    r, a = np.divmod(column, grid.n_alpha)
    p = ((grid.alpha_step * a - grid.unit * v) // grid.psi_step) % grid.n_psi
    # every alpha of rho = 0 has the exact cost of alpha = 0, the lowest index of the tie
    a[grid.identity[r]] = 0
    exact = exact_costs(grid, currents, goal, (pair, r, a, p), ssd)
    index = (r * grid.n_alpha + a) * grid.n_psi + p
    best: dict[int, tuple[float, int]] = {}  # each pair's lowest (cost, index): few candidates
    for q, cost, i in zip(pair.tolist(), exact.tolist(), index.tolist(), strict=True):
        if q not in best or (cost, i) < best[q]:
            best[q] = (cost, i)
    return [(_unravel(best[q][1], grid), best[q][0]) for q in range(k)]


def _tolerance(n: int, norm: float, screen: GoalScreen) -> float:
    """A bound on |float32 score - exact score| of a current signal of norm ``norm`` (with a
    margin): sums of n products (|Q column| <= w, |c| <= norm) and the rounding of Q (<= 8 u
    big per entry), with a factor 2 to spare; the last term: products that underflow
    (absolute error <= 2**-149 each)."""
    w, big = screen.norm, screen.big
    relative = (n + 4) * (norm * w + w * w) + 9.0 * math.sqrt(n) * big * (norm + w)
    return 2.0 * (_U32 * relative + 4 * n * 2.0**-149)


def _unravel(index: int, grid: SearchGrid) -> tuple[int, int, int]:
    """``(r, a, p)`` of the flat index ``(r * n_alpha + a) * n_psi + p``."""
    ra, p = divmod(index, grid.n_psi)
    r, a = divmod(ra, grid.n_alpha)
    return r, a, p
