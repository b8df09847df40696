"""World styles: the kinds of place a generated world can be.

A style is a seeded generator of a base scene (``build(seed, room, grid) -> Scene``, drawing
only from ``default_rng([seed, 0])``) and the lighting of each variant. The variants' added
objects (a plant, chairs) are common to every style (:func:`homebench.data.synth.layout.
variant_objects`); what each variant's light means in a style is in the style's docstring.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import ModuleType

from homebench.data.synth.lighting import Lighting
from homebench.data.synth.scene import Room, Scene
from homebench.data.synth.spec import Style, Variant
from homebench.data.synth.styles import arena, corridor, lab, outdoor, posters
from homebench.geometry import Grid


@dataclass(frozen=True)
class StyleDefinition:
    """One style: its generator, its variants' lighting and its documentation."""

    name: Style
    build: Callable[[int, Room, Grid], Scene]
    lightings: Mapping[Variant, Lighting]
    description: str


def _definition(name: Style, module: ModuleType) -> StyleDefinition:
    doc = (module.__doc__ or "").strip()
    return StyleDefinition(name, module.build, module.LIGHTINGS, doc)


STYLES: dict[Style, StyleDefinition] = {
    "posters": _definition("posters", posters),
    "lab": _definition("lab", lab),
    "corridor": _definition("corridor", corridor),
    "outdoor": _definition("outdoor", outdoor),
    "arena": _definition("arena", arena),
}


def style(name: Style) -> StyleDefinition:
    """The definition of style ``name``."""
    return STYLES[name]
