"""Route navigation by scene familiarity: what perfect memory and Infomax share.

Model (Baddeley, Graham, Husbands & Philippides 2012, PLoS Comput. Biol. 8(1): e1002336): an
agent that has learnt the views of a route, each taken facing the way the route runs, follows
it by scanning: it turns its current view through every rotation, asks its memory how familiar
each looks and moves in the most familiar direction. The memory holds the whole route; no view
is a goal. :mod:`~homebench.methods.familiarity.perfect_memory` keeps every training view,
:mod:`~homebench.methods.familiarity.infomax` trains a network on them.

**The route-memory protocol** (an optional hook beside
:class:`~homebench.methods.base.HomingMethod`; base.py's ``uses_route`` is klt-sector's tracking,
another thing). A method that learns a route sets the
class attribute ``learns_route = True`` and has

- ``describe(view)``: per view, as every method (here the down-sampled image);
- ``learn(views)``: the memory, from the described training views (route order, each facing
  the way to go);
- ``unfamiliarity(memory, current)``: shape (n,), one value per column shift s of the current
  features (lower: more familiar): the memory's rotational image difference function (RIDF);
- ``follow(memory, current)``: a :class:`~homebench.methods.base.HomingEstimate` whose ``angle``
  is the most familiar direction in the current robot frame and ``rotation`` the heading change
  from the most familiar memory view to the current one.

On a pair of views (the grid engine's ``home(current, goal)``) the memory is the goal view
alone, a one-view route: a visual compass. It finds the heading change, but the direction it
points is the one the goal view faced, not the way home, so these methods set
``gives_direction = False`` and a grid run scores their rotation only.

Conventions: features are images (rows, n) in canonical columns (column k looks at azimuth
``2*pi*k/n`` ccw, :mod:`homebench.imaging.horizon`). The current image rolled by s columns
(``np.roll(current, s, axis=-1)``) is what the robot would see after turning by
``-s * 2*pi/n`` (the visual compass's convention), so the most familiar shift s* gives the
direction ``-s* * 2*pi/n`` and the heading change ``s* * 2*pi/n``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from homebench.errors import ConfigError
from homebench.geometry import TWO_PI, PanoramaGeometry, wrap_angle
from homebench.imaging.horizon import horizon_band
from homebench.methods.base import HomingEstimate, View, is_flat
from homebench.methods.param_types import check_fields
from homebench.methods.params import param

FloatArray = NDArray[np.float64]


def learns_route(method: type) -> bool:
    """Whether a method class learns a route (``learns_route``, default False)."""
    return bool(getattr(method, "learns_route", False))


def rotations(image: FloatArray) -> FloatArray:
    """Every column roll of ``image`` (rows, n), flattened: shape (n, rows * n), row s holding
    ``np.roll(image, s, axis=-1)``."""
    n = image.shape[-1]
    index = (np.arange(n)[None, :] - np.arange(n)[:, None]) % n  # [s, k] = k - s
    return image[:, index].transpose(1, 0, 2).reshape(n, -1)


def most_familiar(profile: FloatArray, **diagnostics: Any) -> HomingEstimate:
    """The estimate at the smallest value of an unfamiliarity ``profile`` (n,) over column
    shifts (the first of ties): direction ``-s * 2*pi/n``, rotation ``s * 2*pi/n``, score the
    smallest value."""
    shift = int(np.argmin(profile))
    turn = shift * TWO_PI / profile.size
    return HomingEstimate(
        angle=float(wrap_angle(-turn)),
        rotation=float(wrap_angle(turn)),
        n_landmarks=int(profile.size),
        score=float(profile[shift]),
        diagnostics={"shift": shift, **diagnostics},
    )


@dataclass(frozen=True)
class RouteMemory(ABC):
    """Base of the familiarity methods: the down-sampled views, ``follow``, ``home``."""

    learns_route: ClassVar[bool] = True
    gives_direction: ClassVar[bool] = False

    image_size: tuple[int, int] = param(
        (90, 17),
        "(columns, rows) of the views the memory compares: the whole unfolded panorama "
        "area-averaged in elevation and band-limited in azimuth, grey levels scaled to [0, 1].",
        reading="Baddeley et al. (2012) down-sample the panoramas; the size is not verified "
        "from the paper's text here. 90 x 17 (4 deg per column) follows the authors' group's "
        "public Infomax training code (infomax_train.m: 'number of pixels in input image "
        "(i.e. 17x90 = 1530)')",
    )

    def __post_init__(self) -> None:
        check_fields(self)
        if min(self.image_size) < 1:
            raise ConfigError(f"{getattr(self, 'name', 'method')}: image_size must be positive")

    def describe(self, view: View) -> FloatArray:
        """The view as the memory compares it: (rows, columns) in [0, 1], canonical columns."""
        geometry = view.geometry
        if not isinstance(geometry, PanoramaGeometry):
            raise ConfigError(f"{getattr(self, 'name', 'method')}: needs unfolded panoramas")
        columns, rows = self.image_size
        bottom, top = geometry.elevation_bottom, geometry.elevation_top
        return horizon_band(view.image, geometry, bottom, top, rows, columns) / 255.0

    @abstractmethod
    def learn(self, views: Sequence[FloatArray]) -> Any:
        """The memory of the training ``views`` (each (rows, columns), route order)."""

    @abstractmethod
    def scan(self, memory: Any, current: FloatArray) -> tuple[FloatArray, dict[str, Any]]:
        """Unfamiliarity (n,) of every column shift of ``current``, and diagnostics."""

    def unfamiliarity(self, memory: Any, current: FloatArray) -> FloatArray:
        """The memory's RIDF of ``current``: shape (n,), lower is more familiar."""
        return self.scan(memory, current)[0]

    def follow(self, memory: Any, current: FloatArray) -> HomingEstimate:
        """The most familiar direction (robot frame) and heading change; none when the current
        view has no texture."""
        if is_flat(current):
            return HomingEstimate.none(reason="no texture")
        profile, diagnostics = self.scan(memory, current)
        return most_familiar(profile, **diagnostics)

    def home(self, current: FloatArray, goal: FloatArray) -> HomingEstimate:
        """A one-view route: the heading change only (``angle`` None, see the module)."""
        if is_flat(goal):
            return HomingEstimate.none(reason="no texture")
        return replace(self.follow(self.learn([goal]), current), angle=None)
