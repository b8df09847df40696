"""KLT-sector homing (seed 000): features tracked along the route, home directions by the sector
law."""
