"""Closed-loop homing (``kind: closed-loop``): see, turn, move, from continuous starts.

:mod:`~.config` the config, :mod:`~.starts` the goals and starts, :mod:`~.views` the
rendered views (a fine position lattice, cached on disk and in memory), :mod:`~.homers` what
steers (a registered pairwise method, or the ``truth`` and ``random`` controls), :mod:`~.loop`
one trial's loop, :mod:`~.experiment` trials as jobs and the run, :mod:`~.tables` the metrics,
:mod:`~.floor` the floor plan the report draws on.
"""
