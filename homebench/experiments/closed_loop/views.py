"""What the robot sees: views rendered on a fine position lattice, cached on disk and in memory.

Rendering is the cost of a closed-loop run (about 0.1 s a view). A generated world is
rendered at heading 0 on a square lattice of ``spacing`` metres (the nodes ``(ix, iy) *
spacing`` of the world frame) and the view turned to the robot's heading by whole columns (as
:func:`~homebench.experiments.scene.grid_scene` does). **What the snapping does to the pose:**
the robot sees the view of the lattice node nearest to its true position (at most
``spacing / sqrt(2)`` away: 1.4 cm at 2 cm) and of its heading rounded to a whole column (at
most half a column step: 0.5 deg at 360 columns); the loop itself moves the true, continuous
pose, and success, collisions and path lengths are measured on it. Sensor noise is seeded per
lattice node, so two visits of one node see the same image, and so do two methods.

The disk cache is ``<run>/views/<scene key>/<ix>_<iy>.png``, written atomically (worker
processes share it: a view one worker rendered, the others read). Its size is bounded by
``max_bytes``: each worker sums the folder once and stops writing once that sum plus its own
writes exceed the bound (with n workers the folder may exceed it by n - 1 views). In memory
each worker keeps the last ``memory_views`` views (an LRU).

Grid databases (``lattice`` None there) and ``lattice: null`` render every pose as it is.
"""

from __future__ import annotations

import math
import os
from collections import OrderedDict
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from homebench.errors import DataError
from homebench.experiments.scene import Scene, turned
from homebench.fileio import read_grey, write_png
from homebench.geometry import Pose
from homebench.hashing import derived_seed
from homebench.views import View

Image = NDArray[np.uint8]


class LatticeViews:
    """Views of ``scene`` at any pose, snapped to a lattice of ``spacing`` metres (None: exact).

    ``folder``: the disk cache (None: none); ``seed``: the sensor noise's.
    """

    def __init__(
        self,
        scene: Scene,
        spacing: float | None,
        folder: Path | None,
        max_bytes: float,
        memory_views: int,
        seed: int,
    ) -> None:
        self.scene, self.spacing, self.folder, self.seed = scene, spacing, folder, seed
        self.max_bytes, self.memory_views = max_bytes, memory_views
        self._memory: OrderedDict[tuple[int, int], Image] = OrderedDict()
        self._bytes: float | None = None
        self.rendered = 0  # views this process rendered (the rest came from a cache)

    def node(self, pose: Pose) -> tuple[int, int]:
        """The lattice node nearest to ``pose``, (ix, iy)."""
        assert self.spacing is not None
        return round(pose.x / self.spacing), round(pose.y / self.spacing)

    def see(self, pose: Pose) -> Image:
        """The unfolded panorama (H, W) uint8 the robot sees at ``pose``."""
        if self.spacing is None:
            self.rendered += 1
            noise = derived_seed(self.seed, "exact", pose.x, pose.y, pose.heading)
            return self.scene.render(pose, noise)
        at_zero = self._at_node(self.node(pose))
        return turned(View(at_zero, self.scene.geometry), pose.heading)

    def _at_node(self, node: tuple[int, int]) -> Image:
        if node in self._memory:
            self._memory.move_to_end(node)
            return self._memory[node]
        image = self._from_disk(node)
        if image is None:
            assert self.spacing is not None
            pose = Pose(node[0] * self.spacing, node[1] * self.spacing, 0.0)
            image = self.scene.render(pose, derived_seed(self.seed, "node", *node))
            self.rendered += 1
            self._to_disk(node, image)
        if self.memory_views:
            self._memory[node] = image
            while len(self._memory) > self.memory_views:
                self._memory.popitem(last=False)
        return image

    def _path(self, node: tuple[int, int]) -> Path:
        assert self.folder is not None
        return self.folder / f"{node[0]}_{node[1]}.png"

    def _from_disk(self, node: tuple[int, int]) -> Image | None:
        if self.folder is None:
            return None
        geometry = self.scene.geometry
        try:
            return read_grey(self._path(node), (geometry.width, geometry.height))
        except (FileNotFoundError, DataError):
            return None

    def _to_disk(self, node: tuple[int, int], image: Image) -> None:
        if self.folder is None:
            return
        if self._bytes is None:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._bytes = float(sum(e.stat().st_size for e in os.scandir(self.folder)))
        if self._bytes >= self.max_bytes:
            return
        path = self._path(node)
        write_png(path, image)
        self._bytes += path.stat().st_size


def lattice_error(spacing: float, columns: int) -> tuple[float, float]:
    """Largest position (m) and heading (rad) error of snapping to a lattice of ``spacing``
    metres and to whole columns of a ``columns``-wide panorama."""
    return spacing / math.sqrt(2.0), math.pi / columns
