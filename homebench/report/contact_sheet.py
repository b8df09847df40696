"""A contact sheet of a grid database: every position's panorama laid out as on the floor (a
position without an image left blank), one position large with the manifest's conventions
marked on it; of posed images (a route, any poses), a map of the poses beside one image large.

The marks come from the manifest's camera model through :mod:`homebench.geometry`, so a user
can check a manifest they wrote: on the unfolded panorama, a vertical line at azimuth 0 and
ticks at 90, 180 and 270 deg (where azimuth grows), a horizontal line at the horizon row; on a
raw image, the rays of azimuth 0 and 90 deg from the centre and the horizon circle.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.artist import Artist  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.gridspec import GridSpec  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from homebench.config import UnfoldConfig  # noqa: E402
from homebench.data.database import GridDatabase  # noqa: E402
from homebench.fileio import atomic_write  # noqa: E402
from homebench.geometry import CatadioptricGeometry, Grid, PanoramaGeometry  # noqa: E402
from homebench.imaging.projection import unfold  # noqa: E402
from homebench.views import View  # noqa: E402

#: Panorama width shown for raw-only databases (unfolded on the fly).
SHEET_PANORAMA_WIDTH = 288
#: Colours of the marks: azimuth 0, azimuth 90 deg (raw images), the horizon.
AZIMUTH_0_COLOUR = "#ff2020"
AZIMUTH_90_COLOUR = "#ffb000"
HORIZON_COLOUR = "#20a0ff"
#: Sheet width, width of the grid and of the panels beside it, height of the text (inches).
SHEET_WIDTH, GRID_WIDTH, PANEL_WIDTH, TEXT_HEIGHT = 16.0, 7.0, 5.6, 1.1
#: Largest height of the raw image's panel (inches).
RAW_HEIGHT = 4.2


def _panorama(database: GridDatabase, i: int, j: int) -> View:
    if "unfolded" in database.kinds:
        return database.view(i, j, "unfolded")
    raw = database.view(i, j, "raw")
    geometry = UnfoldConfig(width=SHEET_PANORAMA_WIDTH).geometry()
    return View(unfold(raw.image, raw.geometry, geometry), geometry)


def _grows(direction: str) -> str:
    return "to the right" if direction == "ccw" else "to the left"


def mark_panorama(ax: Axes, geometry: PanoramaGeometry) -> list[Artist]:
    """Mark azimuth 0 (a vertical line at its column, triangles on the image's edges), ticks at
    every 90 deg of azimuth and the horizon (a line at its row) on an axes showing an image of
    ``geometry`` with imshow's default extent (pixel centres at integer coordinates, as in
    :mod:`homebench.geometry`). Returns the azimuth-0 line, the horizon line (if the horizon
    is in the image), the triangles."""
    azimuths = [0.0, 90.0, 180.0, 270.0]
    columns = geometry.azimuth_to_column([math.radians(a) for a in azimuths])
    ax.set_xticks(columns, [f"az {a:.0f}°" for a in azimuths], fontsize=7)
    zero = float(columns[0])
    marks: list[Artist] = [ax.axvline(zero, color=AZIMUTH_0_COLOUR, lw=1.2)]
    row = geometry.horizon_row
    if -0.5 <= row <= geometry.height - 0.5:
        marks.append(ax.axhline(row, color=HORIZON_COLOUR, lw=1.2))
        ax.set_yticks([row], ["horizon"], fontsize=7)
    else:
        ax.set_yticks([])
    edges = [-0.5, geometry.height - 0.5]  # triangles on the image's edges: seen at column 0
    marks += ax.plot(
        [zero, zero], edges, ls="", marker="v", ms=6, color=AZIMUTH_0_COLOUR, clip_on=False
    )
    return marks


def mark_raw(ax: Axes, geometry: CatadioptricGeometry) -> list[Artist]:
    """Mark the rays of azimuth 0 and 90 deg (centre to the outer radius) and the horizon
    circle on an axes showing a raw image of ``geometry`` (imshow's default extent)."""
    cx, cy = geometry.centre
    outer = float(geometry.radius_to_elevation(geometry.outer_radius))
    marks: list[Artist] = []
    for azimuth, colour, label in ((0.0, AZIMUTH_0_COLOUR, "azimuth 0"),
                                   (90.0, AZIMUTH_90_COLOUR, "azimuth 90°")):  # fmt: skip
        u, v = geometry.bearing_to_pixel(math.radians(azimuth), outer)
        line = Line2D([cx, float(u)], [cy, float(v)], color=colour, lw=1.2, label=label)
        marks.append(ax.add_line(line))
    circle = Circle(
        (cx, cy), geometry.horizon_radius, fill=False, color=HORIZON_COLOUR, lw=1.2, label="horizon"
    )
    marks.append(ax.add_patch(circle))
    ax.legend(handles=marks, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7)
    return marks


def conventions_text(database: GridDatabase, i: int, j: int) -> str:
    """The manifest's conventions the marks show, one line each, for the sheet."""
    lines = [f"heading at ({i}, {j}): {math.degrees(database.heading(i, j)):g}°"]
    if "raw" in database.kinds:
        raw = database.geometry("raw")
        assert isinstance(raw, CatadioptricGeometry)
        side = "outside" if raw.up_is_outside else "inside"
        lines += [
            f"raw {raw.width} x {raw.height} px: centre ({raw.centre[0]:g}, {raw.centre[1]:g}), "
            f"horizon radius {raw.horizon_radius:.1f} px, above the horizon {side} it;",
            f"    azimuth 0 at image angle {math.degrees(raw.zero_angle):g}° (ccw from +u), "
            f"azimuth {raw.direction}",
        ]
    pano = _panorama(database, i, j).geometry
    assert isinstance(pano, PanoramaGeometry)
    made = "" if "unfolded" in database.kinds else " (unfolded here from the raw image)"
    lines += [
        f"unfolded {pano.width} x {pano.height} px{made}: azimuth 0 at column "
        f"{pano.zero_column:g}, growing {_grows(pano.direction)};",
        f"    elevation {math.degrees(pano.elevation_top):+.1f}° (top edge) to "
        f"{math.degrees(pano.elevation_bottom):+.1f}° (bottom edge), horizon at row "
        f"{pano.horizon_row:.1f}",
    ]
    return "\n".join(lines)


def centre_sample(grid: Grid) -> tuple[int, int]:
    """The position a sheet shows large by default: the grid's centre, or where it has no
    image (a grid with holes) the nearest position that has one."""
    centre = (grid.shape[0] // 2, grid.shape[1] // 2)
    if grid.contains(*centre):
        return centre
    i, j = grid.nearest_index(grid.position(*centre))
    return int(i), int(j)


def write_contact_sheet(database: GridDatabase, path: Path, sample: tuple[int, int]) -> Path:
    """Write a PNG: the grid of panoramas (x to the right, y up) and, beside it, position
    ``sample`` large (its raw image if the set has raw images, its unfolded panorama) with the
    conventions marked, and the conventions as text. Returns ``path``."""
    nx, ny = database.grid.shape
    heights = _panel_heights(database, sample)
    grid_height = ny * GRID_WIDTH / nx * heights["unfolded"] / PANEL_WIDTH * 1.2
    fig, left, right = _sheet(heights, grid_height)
    cells = left.subgridspec(ny, nx, wspace=0.04, hspace=0.12)
    for i in range(nx):
        for j in range(ny):
            ax = fig.add_subplot(cells[ny - 1 - j, i])
            if database.grid.contains(i, j):
                ax.imshow(_panorama(database, i, j).image, cmap="gray", vmin=0, vmax=255)
            ax.set_xticks([])
            ax.set_yticks([])
            if j == 0:
                ax.set_xlabel(str(i), fontsize=6, labelpad=1)
            if i == 0:
                ax.set_ylabel(str(j), fontsize=6, rotation=0, labelpad=6, va="center")
    _draw_sample(fig, right, database, sample, heights)
    spacing_cm = round(database.grid.spacing * 100)
    title = f"{database.name}: {nx} x {ny} grid, {spacing_cm} cm apart (x to the right, y up)"
    return _save(fig, title, path)


#: Pose labels on a pose sheet, at most (every k-th image is labelled).
POSE_LABELS = 20


def write_pose_sheet(database: GridDatabase, path: Path, sample: int, layout: str) -> Path:
    """Write a PNG of posed images (``database``: posed places, image k at (k, 0)): a map of
    the poses (x to the right, y up; an arrow along each image's heading, some images' index)
    and, beside it, image ``sample`` large with the conventions marked, as on a grid's contact
    sheet; ``layout`` says what the poses are, in words. Returns ``path``."""
    heights = _panel_heights(database, (sample, 0))
    fig, left, right = _sheet(heights, GRID_WIDTH)
    ax = fig.add_subplot(left)
    grid = database.grid
    n = grid.shape[0]
    xy = grid.position(np.arange(n), 0)  # (n, 2) metres
    headings = np.array([database.heading(k, 0) for k in range(n)])  # (n,) radians
    length = 0.6 * grid.spacing
    ax.plot(xy[:, 0], xy[:, 1], color="#bbbbbb", lw=0.6, zorder=1)
    u, v = length * np.cos(headings), length * np.sin(headings)
    ax.quiver(*xy.T, u, v, angles="xy", scale_units="xy", scale=1, width=0.004, color="#404040")
    ax.scatter(xy[sample, 0], xy[sample, 1], s=40, color=AZIMUTH_0_COLOUR, zorder=3)
    for k in range(0, n, max(1, math.ceil(n / POSE_LABELS))):
        ax.annotate(str(k), xy[k], fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("poses: image k at place [k, 0], arrows along the headings", fontsize=9)
    _draw_sample(fig, right, database, (sample, 0), heights)
    return _save(fig, f"{database.name}: {layout} (x to the right, y up)", path)


def _panel_heights(database: GridDatabase, sample: tuple[int, int]) -> dict[str, float]:
    """Heights (inches) of the panels beside the layout: raw image (if any), panorama, text."""
    pano = _panorama(database, *sample)
    heights = {"unfolded": PANEL_WIDTH * pano.image.shape[0] / pano.image.shape[1]}
    if "raw" in database.kinds:
        height, width = database.manifest.section("raw").size[::-1]
        heights = {"raw": min(RAW_HEIGHT, PANEL_WIDTH * height / width), **heights}
    heights["conventions"] = TEXT_HEIGHT
    return heights


def _sheet(heights: dict[str, float], left_height: float) -> tuple[Figure, Any, Any]:
    """A sheet's figure and its two cells: the layout's (left), the sample's (right)."""
    panels_height = sum(heights.values()) * 1.3
    fig = plt.figure(figsize=(SHEET_WIDTH, max(left_height, panels_height) + 1.6), dpi=110)
    outer = GridSpec(1, 2, width_ratios=[1.25, 1], figure=fig, wspace=0.12, top=0.9, bottom=0.06)
    return fig, outer[0], outer[1]


def _draw_sample(
    fig: Figure,
    cell: Any,
    database: GridDatabase,
    sample: tuple[int, int],
    heights: dict[str, float],
) -> None:
    """Position ``sample`` large in ``cell``: its raw image (if any) and panorama with the
    conventions marked, and the conventions as text."""
    si, sj = sample
    pano = _panorama(database, si, sj)
    assert isinstance(pano.geometry, PanoramaGeometry)
    right = cell.subgridspec(len(heights), 1, height_ratios=list(heights.values()), hspace=0.3)
    axes = {panel: fig.add_subplot(right[k]) for k, panel in enumerate(heights)}
    if "raw" in axes:
        raw = database.view(si, sj, "raw")
        assert isinstance(raw.geometry, CatadioptricGeometry)
        axes["raw"].imshow(raw.image, cmap="gray", vmin=0, vmax=255)
        mark_raw(axes["raw"], raw.geometry)
        axes["raw"].set_title(f"raw image at ({si}, {sj})", fontsize=9)
        axes["raw"].set_xticks([])
        axes["raw"].set_yticks([])
    axes["unfolded"].imshow(pano.image, cmap="gray", vmin=0, vmax=255)
    mark_panorama(axes["unfolded"], pano.geometry)
    axes["unfolded"].set_title(
        f"unfolded panorama at ({si}, {sj}); azimuth grows {_grows(pano.geometry.direction)}",
        fontsize=9,
    )
    axes["conventions"].axis("off")
    axes["conventions"].text(
        0, 1, conventions_text(database, si, sj), va="top", fontsize=8, family="monospace"
    )


def _save(fig: Figure, title: str, path: Path) -> Path:
    """Title ``fig``, write it to ``path`` as PNG (atomically) and close it; ``path``."""
    fig.suptitle(title, fontsize=11)
    with atomic_write(Path(path)) as f:
        fig.savefig(f, format="png")
    plt.close(fig)
    return Path(path)
