"""Route experiments (``kind: route``): seed 000's outbound route, stored views, homing leg by leg.

:mod:`~.config` the config, :mod:`~.experiment` trials, jobs (a trial homed by one method) and
the run, :mod:`~.outbound` the outbound drive. klt-sector homes as seed 000 does:
:mod:`~.lifecycle` the feature life-cycle criterion that picks the targets, :mod:`~.visual`
the sector law leg by leg. Every other (pairwise) method: :mod:`~.snapshots` the views stored
on the way out, :mod:`~.pairwise` homing from snapshot to snapshot.
"""
