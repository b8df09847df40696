"""Generated worlds: scene description, textures, panoramic ray caster, variants.

The data layer uses :func:`~homebench.data.synth.world.build_world`,
:class:`~homebench.data.synth.world.World` and
:func:`~homebench.data.synth.world.render_position`. The package itself imports nothing, so
that reading a world's spec (:mod:`homebench.data.synth.spec`, as every job worker does) does
not import the renderer.
"""
