"""Block matching (Vardy and Möller 2005): optical flow between the views by compiled block
search."""
