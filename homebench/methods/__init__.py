"""Homing methods: one module per method; importing this package registers the built-ins."""
