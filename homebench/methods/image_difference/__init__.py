"""Image-difference homing: the visual compass (RIDF), descent in image distance (DID) and
matched-filter DID."""
