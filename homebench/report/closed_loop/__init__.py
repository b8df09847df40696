"""The report of a closed-loop homing run: trajectories, catchment maps, success against
distance."""
