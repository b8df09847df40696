"""``homebench data check``: each image kind's conventions estimated from its images, held
against the manifest (see :mod:`homebench.data.check` for what is estimated how)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.data.check.azimuth import home_estimates
from homebench.data.check.findings import ORDER_KEY, KindCheck, compare
from homebench.data.check.horizon import flow_profile, zero_crossing
from homebench.data.check.pairs import (
    GridIndex,
    NeighbourPair,
    Pair,
    first_per_axis,
    neighbour_pairs,
)
from homebench.data.check.readings import (
    MIN_HOMED,
    Choice,
    Reading,
    choose,
    fit_readings,
    order_truths,
)
from homebench.data.check.rim import Circle, mirror_rim
from homebench.data.database import GridDatabase
from homebench.errors import DataError
from homebench.geometry import CatadioptricGeometry, Direction, PanoramaGeometry, other_direction
from homebench.imaging.projection import unfold
from homebench.methods import registry
from homebench.views import ImageKind, View

Images = Mapping[GridIndex, NDArray[np.uint8]]
Model = PanoramaGeometry | CatadioptricGeometry
FloatArray = NDArray[np.float64]

#: The homing method: min-warping with Möller's defaults but for its band (see the package
#: docstring) ...
METHOD = "min-warping"
#: ... which lies mostly below the horizon, where the floor is near and moves most (deg; cut
#: to the images' elevations), in rows about 1.9 deg high, as min-warping's default band.
BAND_DEG = (-40.0, 5.0)
BAND_ROW_DEG = 1.9
#: Columns of the panorama raw images are unfolded to for homing (min-warping's band's).
BAND_COLUMNS = 288
#: Neighbour pairs homed per axis (x, y) and image kind ...
PAIRS_PER_AXIS = 50
#: ... and of them, those whose dense flow places the horizon.
FLOW_PAIRS_PER_AXIS = 20
#: Raw images whose mean shows the mirror's rim.
RIM_IMAGES = 16
#: The panoramas whose flow places the horizon have at least this many rows per degree ...
FLOW_ROWS_PER_DEG = 3.0
#: ... and, unfolded from raw images, this many columns.
FLOW_COLUMNS = 720


def check_database(db: GridDatabase, seed: int = 0) -> list[KindCheck]:
    """Check every image kind of ``db`` against its images (DataError when the grid has no
    neighbours along x or along y, or too few pairs of them for a verdict)."""
    nx, ny = db.grid.shape
    if nx < 2 or ny < 2:
        raise DataError(
            f"database {db.name!r}: data check homes between neighbours along x and along y; "
            f"its grid is {nx} x {ny}"
        )
    pairs = neighbour_pairs(db.grid, PAIRS_PER_AXIS, seed)
    if len(pairs) < MIN_HOMED:
        raise DataError(
            f"database {db.name!r}: data check homes between grid neighbours and needs "
            f"{MIN_HOMED} pairs for a verdict; its {nx} x {ny} grid gives {len(pairs)}"
        )
    return [_check_kind(db, kind, pairs, seed) for kind in db.kinds]


def _check_kind(
    db: GridDatabase, kind: ImageKind, pairs: list[NeighbourPair], seed: int
) -> KindCheck:
    """The images' model of ``kind``: centre (raw) from the rim, then the grid's order,
    direction and azimuth offset from neighbour homing, then the horizon from neighbour
    flow."""
    needed = sorted({ij for p in pairs for ij in (p.current, p.goal)})
    images = {ij: db.image(*ij, kind) for ij in needed}
    manifest = db.geometry(kind)
    start, rim = images_rim(manifest, images, seed)
    truths = order_truths(db, pairs)
    fits = fit_readings(ORDER_KEY, truths, estimates(start, images, pairs), pairs)
    stated = Reading(ORDER_KEY, db.grid_order, manifest.direction)
    choice = choose(fits, stated, "value" if db.order_in_doubt else "direction")
    some = first_per_axis(pairs, FLOW_PAIRS_PER_AXIS)
    fitted = fitted_model(start, images, choice, stated, [pairs[k] for k in some],
                          {value: truth[some] for value, truth in truths.items()})  # fmt: skip
    shared = db.shared_heading_deg
    heading = ("heading_deg", shared) if shared is not None else None
    return compare(kind, manifest, fitted, choice, stated, rim, heading)


def fitted_model(
    start: Model,
    images: Images,
    choice: Choice,
    stated: Reading,
    flow_pairs: Sequence[Pair],
    flow_truths: Mapping[str, FloatArray],
) -> Model:
    """``start`` with the direction and azimuth zero of the reading the images support, and,
    where they support one, the horizon where the flow between ``flow_pairs`` puts it
    (``flow_truths``: their true home directions under each value of the reading's key)."""
    reading = choice.reading or stated
    fitted = replace(start, direction=reading.direction).turned(choice.fits[reading].offset)
    if choice.reading is None:  # the flow's signs need the images' azimuths
        return fitted
    return with_horizon(fitted, images, flow_pairs, flow_truths[reading.value])


def images_rim(model: Model, images: Images, seed: int) -> tuple[Model, Circle | None]:
    """``model`` with the centre of the mirror rim in :data:`RIM_IMAGES` of the raw ``images``
    (drawn with ``seed``) where one is found, and the rim (None: panoramas, or none found)."""
    if not isinstance(model, CatadioptricGeometry):
        return model, None
    keys = list(images)
    picked = np.random.default_rng(seed).permutation(len(keys))[:RIM_IMAGES]
    rim = mirror_rim([images[keys[k]] for k in picked])
    return (replace(model, centre=rim.centre) if rim is not None else model), rim


def estimates(
    model: Model, images: Images, pairs: list[NeighbourPair]
) -> dict[Direction, FloatArray]:
    """Neighbour homing under ``model``'s direction, then under the other: each pair's
    estimate (radians, NaN: none), by direction."""
    low, high = _elevation_range(model)
    bottom, top = max(BAND_DEG[0], low + 0.5), min(BAND_DEG[1], high - 0.5)
    rows = max(2, round((top - bottom) / BAND_ROW_DEG))
    method = registry.create(METHOD, band_bottom_deg=bottom, band_top_deg=top, n_rows=rows)
    band = PanoramaGeometry.square_pixels(BAND_COLUMNS, math.radians(high), math.radians(low))
    estimates = {}
    for direction in (model.direction, other_direction(model.direction)):
        views = _views(replace(model, direction=direction), images, band)
        estimates[direction] = home_estimates(method, views, pairs)
    return estimates


def _elevation_range(model: Model) -> tuple[float, float]:
    """Lowest and highest elevation (deg) ``model``'s images show."""
    if isinstance(model, PanoramaGeometry):
        return math.degrees(model.elevation_bottom), math.degrees(model.elevation_top)
    return math.degrees(min(model.elevations)), math.degrees(max(model.elevations))


def _views(model: Model, images: Images, band: PanoramaGeometry) -> dict[GridIndex, View]:
    """The views a homing method gets of ``images`` under ``model``: unfolded images as they
    are, raw images unfolded to ``band``."""
    if isinstance(model, PanoramaGeometry):
        return {ij: View(image, model) for ij, image in images.items()}
    return {ij: View(unfold(image, model, band), band) for ij, image in images.items()}


def with_horizon(model: Model, images: Images, pairs: Sequence[Pair], motions: FloatArray) -> Model:
    """``model`` with its horizon where the flow between the neighbours ``pairs`` puts it
    (``motions``: their true azimuths in ``model``'s frame, radians)."""
    needed = {ij for p in pairs for ij in (p.current, p.goal)}
    if isinstance(model, PanoramaGeometry):
        factor = max(1, math.ceil(FLOW_ROWS_PER_DEG * math.degrees(model.row_step)))
        flow_model = replace(model, height=model.height * factor)
        size = (model.width, flow_model.height)
        panoramas = {
            ij: cv2.resize(images[ij], size, interpolation=cv2.INTER_CUBIC) for ij in needed
        }
    else:
        top, bottom = max(model.elevations), min(model.elevations)
        rows = max(2, round(FLOW_ROWS_PER_DEG * math.degrees(top - bottom)))
        flow_model = PanoramaGeometry(FLOW_COLUMNS, rows, top, bottom)
        panoramas = {ij: unfold(images[ij], model, flow_model) for ij in needed}
    row = zero_crossing(flow_profile(panoramas, flow_model, pairs, motions))
    elevation = flow_model.row_to_elevation(row)
    if isinstance(model, PanoramaGeometry):
        return model.horizon_at(float(model.elevation_to_row(elevation)))
    return model.horizon_at(float(model.elevation_to_radius(elevation)))
