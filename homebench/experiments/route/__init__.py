"""Route experiments (``kind: route``): seed 000's outbound route, stored views, homing leg by leg.

:mod:`~.config` the config, :mod:`~.experiment` trials and the run, :mod:`~.outbound` the
outbound drive, :mod:`~.visual` homing along the stored views, :mod:`~.lifecycle` the feature
life-cycle criterion that picks the targets.
"""
