"""Generated worlds: scene description, textures, panoramic ray caster, variants.

The data layer uses :func:`build_world` / :class:`World` and :func:`render_position`.
"""

from homebench.data.synth.world import PoseError, World, build_world, render_position

__all__ = ["PoseError", "World", "build_world", "render_position"]
