"""A run config, read once (:func:`homebench.yamlio.read_yaml`), validated as the kind of
experiment it declares.

``kind: route`` is a :class:`~homebench.experiments.route.config.RouteConfig`, ``kind:
closed-loop`` a :class:`~homebench.experiments.closed_loop.config.ClosedLoopConfig`, anything
else a grid run's :class:`~homebench.config.RunConfig` (:func:`homebench.config.kind_of`). The
robot experiments' config modules are imported only for their kind.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias

from homebench.config import RunConfig, grid_config, kind_of
from homebench.yamlio import YamlDocument

if TYPE_CHECKING:
    from homebench.experiments.closed_loop.config import ClosedLoopConfig
    from homebench.experiments.route.config import RouteConfig

AnyConfig: TypeAlias = "RunConfig | RouteConfig | ClosedLoopConfig"


def validated_config(document: YamlDocument) -> AnyConfig:
    """A config document (:func:`homebench.yamlio.read_yaml`) validated as the kind it declares."""
    kind = kind_of(document.data)
    if kind == "route":
        from homebench.experiments.route.config import route_config

        return route_config(document)
    if kind == "closed-loop":
        from homebench.experiments.closed_loop.config import closed_loop_config

        return closed_loop_config(document)
    return grid_config(document)
