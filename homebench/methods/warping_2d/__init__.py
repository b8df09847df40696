"""2-D warping (Möller 2009): warping in azimuth and elevation, on min-warping's scale planes."""
