"""SIFT-landmark homing (seed 001): matching, mismatch elimination and the movement solver."""
