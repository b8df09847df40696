"""Databases in Vardy's layout written by hand, as a user with real recordings writes one.

The images are a generated world's unfolded panoramas, re-laid by plain numpy into the user's
own conventions: the robot heading 90 deg in the world frame (azimuth 0 looks along +y),
azimuth growing clockwise in the image (the panorama mirrored) and azimuth 0 at column
``ZERO_COLUMN``, written as PGM files under the user's own names; the manifest is YAML text,
not made by homebench. No homebench code maps the columns, so a convention bug of homebench's
cannot cancel out here: a test that homes on these images against the grid's ground truth
sees it.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from homebench.data.catalog import resolve
from homebench.data.generate import generate
from homebench.data.synth.spec import GridSpec, RawImageSpec, WorldSpec

SHAPE = (5, 7)
SPACING = 0.3
#: The column where the user's panoramas show azimuth 0 (the robot's heading).
ZERO_COLUMN = 100
HEADING_DEG = 90

MANIFEST = """\
# Our room, recorded with the lab's robot: {variant} lighting.
schema: 1
name: our-room-{variant}
description: "5 x 7 positions 30 cm apart, unfolded panoramas from the robot's camera"
grid: {{shape: [5, 7], spacing: 0.3, origin: [0.0, 0.0]}}
heading_deg: {heading}
images:
  unfolded:
    folder: panoramas
    pattern: "pano_X{{x:02d}}_Y{{y:02d}}.{{ext}}"
    extensions: [pgm]
    size: [{width}, {height}]
    panorama:
      elevation_top_deg: 45.0
      elevation_bottom_deg: -50.0
      direction: {direction}
      zero_column: {zero_column}
"""


def user_columns(width: int) -> np.ndarray:
    """For each column q of the user's panorama, the column of the generated one that shows
    the same world direction, shape (width,). Generated: column p looks at world angle
    2 pi p / width (ccw from +x, heading 0). The user's: column q looks at robot azimuth
    -2 pi (q - ZERO_COLUMN) / width (cw), world angle that + 90 deg."""
    q = np.arange(width)
    return (ZERO_COLUMN - q + width * HEADING_DEG // 360) % width


def write_database(folder: Path, variant: str = "original") -> Path:
    """Write the ``variant`` set of the room to ``folder`` (images under ``panoramas/``,
    ``manifest.yaml`` beside them); returns the manifest's path."""
    spec = WorldSpec(
        variant=variant,
        grid=GridSpec(shape=SHAPE, spacing=SPACING),
        raw=RawImageSpec(width=96, height=72, inner_radius=4.0, outer_radius=34.0),
    )
    generated = resolve(str(generate(spec, None, 2, f"vardy-layout-{variant}")))
    (folder / "panoramas").mkdir(parents=True, exist_ok=True)
    height = width = 0
    for i in range(SHAPE[0]):
        for j in range(SHAPE[1]):
            image = cv2.imread(str(generated.path(i, j, "unfolded")), cv2.IMREAD_GRAYSCALE)
            height, width = image.shape
            path = folder / "panoramas" / f"pano_X{i:02d}_Y{j:02d}.pgm"
            assert cv2.imwrite(str(path), image[:, user_columns(width)])
    manifest = folder / "manifest.yaml"
    manifest.write_text(
        MANIFEST.format(
            variant=variant,
            heading=HEADING_DEG,
            width=width,
            height=height,
            direction="cw",
            zero_column=ZERO_COLUMN,
        )  # fmt: skip
    )
    return manifest
