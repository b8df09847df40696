"""Min-warping (Möller 2009; Möller, Krzykawski and Gerstmayr 2010): the scale-plane search, its
compiled kernels and the workers' preload."""
