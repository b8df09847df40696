"""A texture atlas with a per-tile mip pyramid, sampled with one ``cv2.remap`` per level.

Each texture becomes a tile padded with :data:`GUTTER` replicated texels; each tile gets its own
pyramid (``cv2.pyrDown``), so no level ever mixes two textures. Tiles are packed in shelves in
a fixed order, base textures first: appending textures (a variant's objects) never moves a base
tile. Level-l coordinates are level-0 coordinates / 2**l (pyrDown centres on even texels).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

LEVELS = 4
GUTTER = 16
_ALIGN = 2 ** (LEVELS - 1)
_MIN_WIDTH = 4096

Float32 = NDArray[np.float32]


def _round_up(n: int) -> int:
    return -(-n // _ALIGN) * _ALIGN


@dataclass(frozen=True)
class Region:
    """Where a texture of ``size`` = (cols, rows) texels sits in the atlas (level 0)."""

    x0: int
    y0: int
    size: tuple[int, int]
    scale: tuple[float, float]  # texels per metre along u and v

    @property
    def density(self) -> float:
        """Texels per metre that decide the mip level: the denser of the two directions."""
        return max(self.scale)

    def coords(self, u: NDArray, v: NDArray) -> tuple[Float32, Float32]:
        """Level-0 atlas coordinates of surface points (u, v) in metres, clamped to the tile."""
        x = np.clip(u * self.scale[0] - 0.5, 0.0, self.size[0] - 1) + self.x0
        y = np.clip(v * self.scale[1] - 0.5, 0.0, self.size[1] - 1) + self.y0
        return x.astype(np.float32), y.astype(np.float32)


def layout(
    shapes: list[tuple[int, int]], scales: list[tuple[float, float]], n_base: int
) -> tuple[list[Region], tuple[int, int]]:
    """Shelf-pack textures of ``shapes`` (rows, cols): the first ``n_base`` (tallest first),
    then the rest. Returns a region per texture (input order) and the atlas (rows, cols)."""
    tiles = [(_round_up(h + 2 * GUTTER), _round_up(w + 2 * GUTTER)) for h, w in shapes]
    width = max(_MIN_WIDTH, *(w for _, w in tiles))

    def tallest_first(idx: range) -> list[int]:
        return sorted(idx, key=lambda k: -tiles[k][0])

    order = tallest_first(range(n_base)) + tallest_first(range(n_base, len(shapes)))
    origins: dict[int, tuple[int, int]] = {}
    x = y = shelf = 0
    for k in order:
        th, tw = tiles[k]
        if x + tw > width:
            x, y, shelf = 0, y + shelf, 0
        origins[k] = (x, y)
        x, shelf = x + tw, max(shelf, th)
    regions = [
        Region(origins[k][0] + GUTTER, origins[k][1] + GUTTER, (w, h), scales[k])
        for k, (h, w) in enumerate(shapes)
    ]
    return regions, (y + shelf, width)


class Atlas:
    """Textures packed by :func:`layout`, with ``LEVELS`` pyramid levels (float32)."""

    def __init__(self, textures: list[Float32], regions: list[Region], shape: tuple[int, int]):
        self.regions = regions
        self.levels = [
            np.zeros((-(-shape[0] // 2**lv), -(-shape[1] // 2**lv)), np.float32)
            for lv in range(LEVELS)
        ]
        for tex, region in zip(textures, regions, strict=True):
            tile = cv2.copyMakeBorder(
                np.ascontiguousarray(tex, np.float32),
                GUTTER,
                GUTTER,
                GUTTER,
                GUTTER,
                cv2.BORDER_REPLICATE,
            )
            x0, y0 = region.x0 - GUTTER, region.y0 - GUTTER
            for lv, level in enumerate(self.levels):
                h, w = tile.shape
                level[(y0 >> lv) : (y0 >> lv) + h, (x0 >> lv) : (x0 >> lv) + w] = tile
                if lv + 1 < LEVELS:
                    tile = cv2.pyrDown(tile)

    def sample(self, x: Float32, y: Float32, level: Float32) -> Float32:
        """Trilinear samples at level-0 coordinates (x, y) and fractional mip ``level``.

        All arrays (h, w); ``level`` in [0, LEVELS - 1].
        """
        out = np.zeros(x.shape, np.float32)
        for lv, image in enumerate(self.levels):
            weight = np.maximum(1.0 - np.abs(level - np.float32(lv)), 0.0)
            if not weight.any():
                continue
            scale = np.float32(0.5**lv)
            sample = cv2.remap(
                image, x * scale, y * scale, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
            )
            out += weight * sample
        return out
