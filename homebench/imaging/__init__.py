"""Catadioptric <-> unfolded panorama, horizon extraction, image filters."""
