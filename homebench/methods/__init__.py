"""Homing methods: a package per family, a module per method; importing this package registers
the built-ins. The modules beside the families are what every method shares: the protocol
(:mod:`~homebench.methods.base`), the registry, the parameter cards and the thread limit."""

import homebench.methods.block_matching.method
import homebench.methods.familiarity.infomax
import homebench.methods.familiarity.perfect_memory
import homebench.methods.image_difference.did
import homebench.methods.image_difference.mfdid
import homebench.methods.image_difference.visual_compass
import homebench.methods.klt_sector.method
import homebench.methods.landmarks.alv
import homebench.methods.landmarks.snapshot
import homebench.methods.min_warping.method
import homebench.methods.sift.method
import homebench.methods.warping.fourier
import homebench.methods.warping.method
import homebench.methods.warping_2d.method  # noqa: F401  (importing registers the built-ins)
