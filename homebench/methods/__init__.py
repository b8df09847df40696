"""Homing methods: one module per method; importing this package registers the built-ins."""

from homebench.methods import min_warping, warping  # noqa: F401  (registers the built-ins)
