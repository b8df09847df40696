"""Pair planning, jobs, cache / resume, metrics (AE, AHC, RR), route homing."""
