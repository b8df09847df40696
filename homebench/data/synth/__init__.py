"""Generated worlds: scene description, textures, panoramic ray caster, variants."""
