"""Validation of DID (Zeil, Hofmann and Chahl 2003) on its paper's scene: an image distance that
grows smoothly with the distance from the goal (their translational image difference
function), so that descending it leads home.

The equal-distance arena (rendered panoramas of the round arena's smooth wall texture, the
goal at its centre, tests/validation_scenes.py):

1. **The image difference function**: the RMS difference to the goal view is 0 at the goal and
   rises at every 5 cm step along 8 directions out to 1.5 m (measured 8-11 grey levels at
   5 cm, 53-60 at 1.5 m): one clear minimum in a smooth function.
2. **Descent**: the gradient fitted over neighbours 0.1 m away, at 36 places 0.3, 0.6 and 0.9 m
   from the goal in 12 directions. Measured: AHC 0.997 (mean AE 4.6 deg), at most 16 deg;
   held to AHC 0.99 and 25 deg.
"""

from __future__ import annotations

import numpy as np
from synthetic_panorama import render
from validation_scenes import CENTRE, ahc, neighbour_error, ring

from homebench.methods.image_difference.did import DescentInImageDistances, image_distance

STEP = 0.1  # metres between a place and its neighbours


def test_the_image_distance_rises_smoothly_from_the_goal():
    method = DescentInImageDistances()
    goal = method.describe(render(CENTRE))
    steps = np.arange(0.0, 1.5001, 0.05)
    places = ring(steps, 8)  # distance-major: row d of the reshaped array is steps[d]
    distances = np.reshape(
        [image_distance(method.describe(render(place)), goal) for place in places], (-1, 8)
    )
    assert np.all(distances[0] == 0.0)
    assert np.all(np.diff(distances, axis=0) > 0.0)


def test_descent_near_the_goal():
    method = DescentInImageDistances()
    errors = [neighbour_error(method, CENTRE, place, STEP) for place in ring((0.3, 0.6, 0.9), 12)]
    degrees = np.degrees(errors)
    assert ahc(degrees) > 0.99 and degrees.max() < 25.0
