"""The kinds of experiment, each a subpackage over the one engine of :mod:`homebench.evaluation`.

- **grid** (``kind: grid``, the default): pairs of grid images, the papers' AE / AHC / RR; its
  config is :mod:`homebench.config`, its jobs, tables and statistics are the engine's own
  (:mod:`homebench.evaluation`).
- **route** (``kind: route``, :mod:`homebench.experiments.route`): seed 000's route following.
- **closed-loop** (``kind: closed-loop``, :mod:`homebench.experiments.closed_loop`): homing as a
  robot does it, see - turn - move, from continuous starts.

Shared by the robot experiments: the motion model (:mod:`~homebench.experiments.robot`) and the
scene a robot sees (:mod:`~homebench.experiments.scene`).
"""
