"""Horizon landmarks: sectors of the horizon, the average landmark vector (ALV) and the snapshot
model."""
