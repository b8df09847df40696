"""Homing methods: one module per method; importing this package registers the built-ins."""

from homebench.methods import klt_sector, min_warping, sift, warping  # noqa: F401  (registers the built-ins)
