"""1-D warping (Franz et al. 1998) and its Fourier variant (Stürzl and Mallot 2006)."""
