"""The report of a grid run: home-vector fields, AE maps, metric figures and heat maps."""
