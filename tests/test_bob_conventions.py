"""homebench's reading of Brains on Board databases held against facts from BoB's own files,
not against folders homebench wrote (homebench/data/bob/conventions.py says how each was read).

The numbers are typed in from BoB's repository (BrainsOnBoard/bob_robotics, GPL: no file of it
is copied here):

- ``docs_source/example_image_databases/example_route/database_entries.csv``: three poses of
  an Ant World route rendered by ``ant_world_db_creator`` (720 x 150, camera ``opengl``);
- what its images show, measured on them with OpenCV (grey levels): the horizontal flow from
  image 0 to image 1 (DIS, preset medium, rows 60-149, columns wrapped) vanishes at column 364
  where it diverges (the focus of expansion) and at column 719 where it converges;
  ``cv2.phaseCorrelate`` finds image 2 shifted 1.92 px to the right of image 1;
- ``example_grid``: a render of BoB's Ant World mesh at (0, 1) m matches the image labelled
  Grid (1, 0) (mean absolute difference 0.0047 on a 0-1 scale; 0.066 at its label);
- ``src/navigation/image_database.cc`` / ``include/navigation/image_database.h``: the grid
  recorder's two orders.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from homebench.data.bob import open_bob
from homebench.data.grid_order import (
    GRID_ORDERS,
    label_of,
    label_shape,
    position_of,
    position_shape,
    same_mapping,
)
from homebench.geometry import HeadingConvention, angle_diff

#: example_route's rows: X [mm], Y [mm], Heading [degrees] (Z is 10 mm).
EXAMPLE_ROUTE = [
    (6300.0, 8450.0, 219.962),
    (6293.58, 8442.34, 219.962),
    (6287.26, 8434.58, 219.159),
]
#: Measured on example_route's images (see the module docstring).
EXPANSION_COLUMN, CONTRACTION_COLUMN, SHIFT_1_TO_2_PX = 364.0, 719.0, 1.92
#: example_route's metadata, as BoB's ImageDatabase wrote it.
ROUTE_METADATA = """\
%YAML:1.0
---
metadata:
   time: "2019-01-29 13:07:15"
   type: route
   camera:
      name: opengl
      resolution: [ 720, 150 ]
      isPanoramic: 0
   needsUnwrapping: 0
   isGreyscale: 0
"""


@pytest.fixture
def example_route(tmp_path: Path) -> Path:
    """example_route's entries and metadata (its images are not needed to read its poses)."""
    lines = ["X [mm], Y [mm], Z [mm], Heading [degrees], Filename"]
    lines += [f"{x:g}, {y:g}, 10, {h:g}, image_{k:05d}.png" for k, (x, y, h) in
              enumerate(EXAMPLE_ROUTE)]  # fmt: skip
    (tmp_path / "database_entries.csv").write_text("\n".join(lines) + "\n")
    (tmp_path / "database_metadata.yaml").write_text(ROUTE_METADATA)
    return tmp_path


def _travel_deg(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """The direction (deg ccw from +x) of the step from pose a to pose b."""
    return math.degrees(math.atan2(b[1] - a[1], b[0] - a[0]))


def _off_deg(a_deg: float, b_deg: float) -> float:
    return abs(math.degrees(angle_diff(math.radians(a_deg), math.radians(b_deg))))


def test_example_route_headings_read_as_the_direction_of_travel(example_route: Path) -> None:
    """BoB's route tool renders image k at a distance along the route with the heading of the
    segment it lies on (images 0 and 1 on the segment 0 -> 1, image 2 on 1 -> 2): each heading,
    as homebench reads it, is that segment's direction to 0.1 deg. Read as homebench used to
    (ccw from +x) they were 10 deg off."""
    db = open_bob(example_route)
    for k, (a, b) in enumerate([(0, 1), (0, 1), (1, 2)]):
        travel = _travel_deg(EXAMPLE_ROUTE[a], EXAMPLE_ROUTE[b])
        assert _off_deg(db.heading_deg[k], travel) < 0.1
        as_ccw = float(HeadingConvention(0.0, "ccw").to_world_deg(EXAMPLE_ROUTE[k][2]))
        assert _off_deg(as_ccw, travel) > 9.0


def test_example_route_images_look_where_bob_renders_them(example_route: Path) -> None:
    """The reading's camera model puts straight ahead (the direction of travel, = the heading)
    where the flow between BoB's images 0 and 1 expands, straight behind where it contracts,
    and turns image 1 into image 2 by the shift measured between them."""
    db = open_bob(example_route)
    camera = db.camera
    ahead, behind = camera.azimuth_to_column(0.0), camera.azimuth_to_column(math.pi)
    assert abs(float(ahead) - EXPANSION_COLUMN) < 6.0
    off = abs(float(behind) - CONTRACTION_COLUMN)
    assert min(off, 720 - off) < 6.0
    turn = math.radians(db.heading_deg[2] - db.heading_deg[1])  # ccw, from image 1 to image 2
    shift = camera.columns_for_rotation(turn)
    assert shift > 0 and abs(shift - SHIFT_1_TO_2_PX) < 0.5
    rows = camera.row_to_elevation(np.array([0, 119.5, 149]))
    assert np.degrees(rows) == pytest.approx([59.75, 0.0, -14.75])  # +60 to -15 deg


def test_bob_recorders_order_labels_the_example_grid_transposed() -> None:
    """GridRecorder::getPositions() visits (k // ny, k % ny); record() labels the k-th image
    (k % nx, k // nx): on example_grid (2 x 2) the image labelled (1, 0) was taken at (0, 1)."""
    assert position_of("bob-recorder", (1, 0), (2, 2)) == (0, 1)
    assert position_of("bob-recorder", (0, 1), (2, 2)) == (1, 0)
    nx, ny = 3, 2  # on other grids the labels are scrambled: the k-th visit, the k-th label
    visits = [(x, y) for x in range(nx) for y in range(ny)]
    labels = [(k % nx, k // nx) for k in range(nx * ny)]
    for visit, label in zip(visits, labels, strict=True):
        assert position_of("bob-recorder", label, (nx, ny)) == visit
        assert label_of("bob-recorder", visit, (nx, ny)) == label


@pytest.mark.parametrize("shape", [(1, 1), (1, 4), (3, 1), (3, 3), (4, 6), (7, 2)])
def test_every_order_is_a_bijection_and_label_of_inverts_it(shape: tuple[int, int]) -> None:
    for order in GRID_ORDERS:
        labels = label_shape(order, shape)
        assert position_shape(order, labels) == shape
        positions = {
            position_of(order, (a, b), shape) for a in range(labels[0]) for b in range(labels[1])
        }
        assert positions == set(itertools.product(range(shape[0]), range(shape[1])))
        for i, j in positions:
            assert position_of(order, label_of(order, (i, j), shape), shape) == (i, j)
    for first, second in itertools.combinations(GRID_ORDERS, 2):
        alike = label_shape(first, shape) == label_shape(second, shape) and all(
            position_of(first, (a, b), shape) == position_of(second, (a, b), shape)
            for a in range(label_shape(first, shape)[0])
            for b in range(label_shape(first, shape)[1])
        )
        assert same_mapping(first, second, shape) == alike
