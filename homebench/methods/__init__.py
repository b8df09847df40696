"""Homing methods: one module per method; importing this package registers the built-ins."""

from homebench.methods import (  # noqa: F401  (importing registers the built-ins)
    alv,
    block_matching,
    did,
    fourier_warping,
    infomax,
    klt_sector,
    mfdid,
    min_warping,
    perfect_memory,
    sift,
    snapshot,
    visual_compass,
    warping,
    warping_2d,
)
