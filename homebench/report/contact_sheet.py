"""A contact sheet of a grid database: every position's panorama laid out as on the floor."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.gridspec import GridSpec  # noqa: E402

from homebench.config import UnfoldConfig  # noqa: E402
from homebench.data.database import GridDatabase  # noqa: E402
from homebench.fileio import atomic_write  # noqa: E402
from homebench.imaging.projection import unfold  # noqa: E402
from homebench.methods.base import View  # noqa: E402

#: Panorama width shown for raw-only databases (unfolded on the fly).
SHEET_PANORAMA_WIDTH = 288


def _panorama(database: GridDatabase, i: int, j: int) -> View:
    if "unfolded" in database.kinds:
        return database.view(i, j, "unfolded")
    raw = database.view(i, j, "raw")
    geometry = UnfoldConfig(width=SHEET_PANORAMA_WIDTH).geometry()
    return View(unfold(raw.image, raw.geometry, geometry), geometry)


def write_contact_sheet(database: GridDatabase, path: Path, sample: tuple[int, int]) -> Path:
    """Write a PNG: the grid of panoramas (x to the right, y up) and one raw + unfolded pair.

    ``sample`` is the grid position shown large. Returns ``path``.
    """
    nx, ny = database.grid.shape
    fig = plt.figure(figsize=(16, 9), dpi=110)
    outer = GridSpec(1, 2, width_ratios=[1.25, 1], figure=fig, wspace=0.08)
    cells = outer[0].subgridspec(ny, nx, wspace=0.04, hspace=0.12)
    for i in range(nx):
        for j in range(ny):
            ax = fig.add_subplot(cells[ny - 1 - j, i])
            ax.imshow(_panorama(database, i, j).image, cmap="gray", vmin=0, vmax=255)
            ax.set_xticks([])
            ax.set_yticks([])
            if j == 0:
                ax.set_xlabel(str(i), fontsize=6, labelpad=1)
            if i == 0:
                ax.set_ylabel(str(j), fontsize=6, rotation=0, labelpad=6, va="center")
    right = outer[1].subgridspec(2, 1, height_ratios=[2.2, 1], hspace=0.2)
    si, sj = sample
    if "raw" in database.kinds:
        raw = database.view(si, sj, "raw")
        ax = fig.add_subplot(right[0])
        ax.imshow(raw.image, cmap="gray", vmin=0, vmax=255)
        ax.set_title(f"raw image at ({si}, {sj})", fontsize=9)
        ax.axis("off")
    ax = fig.add_subplot(right[1])
    ax.imshow(_panorama(database, si, sj).image, cmap="gray", vmin=0, vmax=255)
    ax.set_title(f"unfolded panorama at ({si}, {sj}); azimuth grows to the right", fontsize=9)
    ax.axis("off")
    spacing_cm = round(database.grid.spacing * 100)
    fig.suptitle(
        f"{database.name}: {nx} x {ny} grid, {spacing_cm} cm apart (x to the right, y up)",
        fontsize=11,
    )
    with atomic_write(Path(path)) as f:
        fig.savefig(f, format="png")
    plt.close(fig)
    return Path(path)
