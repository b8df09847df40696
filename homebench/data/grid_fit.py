"""The regular grid that recorded positions with grid indices lie on, or why there is none.

homebench's grid puts index (i, j) at ``origin + (i, j) * spacing``: one spacing, axes along x
and y, indices growing with the coordinates. A recording gives positions (measured, rounded to
millimetres, or computed by a grid recorder) and indices; the grid fitted to them by least
squares must hold every position within :data:`TOLERANCE` of a spacing (at least
:data:`MIN_TOLERANCE_M`), else the layout is refused with the reason.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from homebench.errors import DataError
from homebench.geometry import Grid

#: Largest distance between a position and its grid point, in spacings ...
TOLERANCE = 0.05
#: ... and at least this, metres.
MIN_TOLERANCE_M = 0.001
#: Fitted spacings and origins are rounded to this many decimals (nanometres).
DECIMALS = 9


def fit_grid(
    xy: NDArray[np.float64], ij: NDArray[np.int64], source: str, where: Callable[[int], str]
) -> Grid:
    """The grid of positions ``xy`` (n, 2) metres at indices ``ij`` (n, 2) (each index once;
    the grid spans them from 0, some may be missing), read from ``source``, whose entry k
    ``where(k)`` names in errors. DataError saying why when the positions lie on no regular
    grid of homebench's kind."""
    if len(ij) < 2:
        raise DataError(f"{source}: a grid of {len(ij)} recorded position(s) has no spacing")
    shape = (int(ij[:, 0].max()) + 1, int(ij[:, 1].max()) + 1)
    varies = [bool(np.ptp(ij[:, k]) > 0) for k in (0, 1)]
    slopes = {axis: _slope(ij[:, k], xy[:, k]) for k, axis in enumerate("xy") if varies[k]}
    for axis, slope in slopes.items():
        if slope <= 0:
            raise DataError(
                f"{source}: the grid index along {axis} grows as {axis} falls (spacing "
                f"{slope:+.4g} m); homebench's grid indices grow with the coordinates"
            )
    spacing = float(np.mean(list(slopes.values())))
    tolerance = max(TOLERANCE * spacing, MIN_TOLERANCE_M)
    if max(slopes.values()) - min(slopes.values()) > tolerance:
        raise DataError(
            f"{source}: the grid is {slopes['x']:.4g} m apart along x and {slopes['y']:.4g} m "
            "along y; homebench's grids have one spacing"
        )
    origin = np.mean(xy - ij * spacing, axis=0)
    off = np.hypot(*(xy - (origin + ij * spacing)).T)
    worst = int(np.argmax(off))
    if off[worst] > tolerance:
        i, j = ij[worst]
        raise DataError(
            f"{where(worst)}: grid position ({i}, {j}) at ({xy[worst, 0]:.3f}, "
            f"{xy[worst, 1]:.3f}) m lies {off[worst]:.3f} m off the regular grid "
            f"{spacing:.4g} m apart that the positions fit (tolerance {tolerance:.3f} m)"
        )
    origin_xy = (round(float(origin[0]), DECIMALS), round(float(origin[1]), DECIMALS))
    return Grid(shape, round(spacing, DECIMALS), origin_xy)


def _slope(index: NDArray[np.int64], coordinate: NDArray[np.float64]) -> float:
    """Least-squares slope of ``coordinate`` over ``index`` (metres per index)."""
    d = index - index.mean()
    return float(np.sum(d * (coordinate - coordinate.mean())) / np.sum(d * d))
