"""Views: one panoramic image with the camera model that made it, and the two kinds of image.

A low module (it needs only :mod:`homebench.geometry`) so that the data, imaging and
evaluation layers can hold views without importing the methods; methods see the same
:class:`View` (re-exported by :mod:`homebench.methods.base`, their interface).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry

#: The two kinds of image a database holds: the raw catadioptric image and the unfolded
#: panorama.
ImageKind = Literal["raw", "unfolded"]


@dataclass(frozen=True)
class View:
    """One grey-level image (shape (height, width), uint8) with the camera model that made it."""

    image: NDArray[np.uint8]
    geometry: PanoramaGeometry | CatadioptricGeometry

    @property
    def kind(self) -> ImageKind:
        return "raw" if isinstance(self.geometry, CatadioptricGeometry) else "unfolded"
