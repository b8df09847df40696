"""The report of a route-homing run (seed 000): trials, statistics, paired tests, figures."""
