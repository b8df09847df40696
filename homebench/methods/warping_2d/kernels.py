"""Compiled (numba) kernels of 2D-warping: the goal warped for every (rho, alpha), and the row
sums of its spectra against the current band's.

Both return bit for bit what the pure-numpy reading in :mod:`homebench.methods.warping_2d.method`
returns (:meth:`~homebench.methods.warping_2d.method.Warping2D.warped_goals` and the spectrum sums
of
:meth:`~homebench.methods.warping_2d.method.Warping2D.costs`): the same float64 operations in the
same
order, each rounded once (no ``fastmath``: no reassociation, no fused multiply-add), so vector
width does not change a result. No ``parallel``; ``nogil`` lets threads share a process.

Compilation as :mod:`homebench.methods.min_warping.kernels`: one signature per kernel, compiled
(or loaded from numba's cache in this package's ``__pycache__``) when the module is imported,
which a run's worker server does before it forks the workers (the method's
``preload_modules``); inputs are declared read-only (feature files are read into read-only
arrays; writable ones convert).
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
IntArray = NDArray[np.intp]


def _array(dtype: types.Type, ndim: int, readonly: bool = False) -> types.Array:
    return types.Array(dtype, ndim, "C", readonly=readonly)


_F64_2D, _C128_2D = _array(types.float64, 2, True), _array(types.complex128, 2, True)
#: The one signature each kernel is compiled for.
SIGNATURES = {
    "warp_goal": types.void(
        _F64_2D,
        _array(types.intp, 2, True),
        _F64_2D,
        _array(types.intp, 3, True),
        _array(types.float64, 3, True),
        _array(types.float64, 3),
    ),
    "spectrum_sums": types.void(
        _array(types.complex128, 3, True), _C128_2D, _array(types.complex128, 2)
    ),
}


@njit(SIGNATURES["warp_goal"], cache=True, nogil=True)
def warp_goal(
    goal: FloatArray,
    low: IntArray,
    frac: FloatArray,
    rows: IntArray,
    weight: FloatArray,
    out: FloatArray,
) -> None:
    """Write the goal band (stored rows, n) warped for every (rho, alpha) into ``out`` (n_rho *
    n_alpha, rows, n): column k of hypothesis h interpolates the goal's columns ``low[h, k]``
    and the next (circular) by ``frac[h, k]``, then row r of that column the stored rows
    ``rows[h, k, r]`` and the next (the last row clamped) by ``weight[h, k, r]``."""
    n_stored, n = goal.shape
    column = np.empty(n_stored)
    for h in range(out.shape[0]):
        for k in range(n):
            left, f = low[h, k], frac[h, k]
            right = left + 1 if left + 1 < n else 0
            for s in range(n_stored):
                column[s] = (1.0 - f) * goal[s, left] + f * goal[s, right]
            for r in range(out.shape[1]):
                below = rows[h, k, r]
                above = below + 1 if below + 1 < n_stored else n_stored - 1
                w = weight[h, k, r]
                out[h, r, k] = (1.0 - w) * column[below] + w * column[above]


@njit(SIGNATURES["spectrum_sums"], cache=True, nogil=True)
def spectrum_sums(warped: ComplexArray, band: ComplexArray, out: ComplexArray) -> None:
    """Write ``sum over rows r of warped[h, r] * conj(band[r])`` into ``out[h]`` (h, f): the
    spectra of the warped goals (h, rows, f) against the current band's (rows, f); each product
    as ``(wr br + wi bi) + (wi br - wr bi) i``, summed from row 0 on."""
    n_rows, n_freq = band.shape
    real, imag = np.empty(n_freq), np.empty(n_freq)
    for h in range(warped.shape[0]):
        row = warped[h]
        for f in range(n_freq):
            w, b = row[0, f], band[0, f]
            real[f] = w.real * b.real + w.imag * b.imag
            imag[f] = w.imag * b.real - w.real * b.imag
        for r in range(1, n_rows):
            for f in range(n_freq):
                w, b = row[r, f], band[r, f]
                real[f] += w.real * b.real + w.imag * b.imag
                imag[f] += w.imag * b.real - w.real * b.imag
        for f in range(n_freq):
            out[h, f] = complex(real[f], imag[f])
