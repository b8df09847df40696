"""Route following by scene familiarity (Baddeley et al. 2012): perfect memory and Infomax."""
