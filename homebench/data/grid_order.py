"""How a grid database's labels (the grid index in a file's name or its entries row) map to
the positions its images were taken at.

- ``as-written``: the label is the position.
- ``transposed``: the image labelled (a, b) was taken at (b, a): x and y swapped, which
  mirrors every direction about the line x = y.
- ``bob-recorder``: the order Brains on Board's grid recorder gives the Ant World tools. In
  BoB robotics, ``ImageDatabase::GridRecorder::getPositions()``
  (``src/navigation/image_database.cc``) lists the positions x-outer, y-inner (image k at
  (k // ny, k % ny)), while ``GridRecorder::record(image)``
  (``include/navigation/image_database.h``) labels the k-th image it is given advancing x
  fastest ((k % nx, k // nx)); ``tools/ant_world_db_creator`` renders each position of the
  first list and records it with the second. On a square grid this is ``transposed``; on
  others the labels are scrambled. Checked on BoB's own ``example_grid`` (2 x 2, 1 m apart):
  a render of BoB's Ant World mesh at (0, 1) m matches the image labelled (1, 0) to a mean
  absolute difference of 0.0047 (0-1 scale) and the one labelled (0, 1) to 0.066.

``nx, ny`` (``shape``) is the grid's size in positions, as the recorder knew it (BoB's
``metadata.grid.size``). Every function here is a bijection between labels and positions of
that grid; a transposed grid's labels span (ny, nx).
"""

from __future__ import annotations

from typing import Literal, get_args

GridOrder = Literal["as-written", "transposed", "bob-recorder"]
#: Every order, the default first.
GRID_ORDERS: tuple[GridOrder, ...] = get_args(GridOrder)
Index = tuple[int, int]


def position_of(order: GridOrder, label: Index, shape: Index) -> Index:
    """The grid position (i, j) of the image labelled ``label`` on a grid of ``shape``
    positions (nx, ny)."""
    a, b = label
    if order == "as-written":
        return a, b
    if order == "transposed":
        return b, a
    nx, ny = shape
    k = b * nx + a  # the k-th image recorded
    return k // ny, k % ny


def label_of(order: GridOrder, position: Index, shape: Index) -> Index:
    """The label of the image taken at ``position`` (i, j) on a grid of ``shape`` (nx, ny)."""
    i, j = position
    if order == "as-written":
        return i, j
    if order == "transposed":
        return j, i
    nx, ny = shape
    k = i * ny + j
    return k % nx, k // nx


def label_shape(order: GridOrder, shape: Index) -> Index:
    """The span of the labels of a grid of ``shape`` positions (nx, ny)."""
    return (shape[1], shape[0]) if order == "transposed" else shape


def position_shape(order: GridOrder, labels: Index) -> Index:
    """The positions' shape of a grid whose labels span ``labels``."""
    return (labels[1], labels[0]) if order == "transposed" else labels


def same_mapping(first: GridOrder, second: GridOrder, shape: Index) -> bool:
    """Whether two orders map every label of a grid of ``shape`` (nx, ny) alike: on a square
    grid ``transposed`` and ``bob-recorder`` do, on a grid of one row or column
    ``as-written`` and ``bob-recorder`` (the recorder's two lists then agree)."""
    if first == second:
        return True
    nx, ny = shape
    pair = {first, second}
    if pair == {"transposed", "bob-recorder"}:
        return nx == ny
    if pair == {"as-written", "bob-recorder"}:
        return nx == 1 or ny == 1
    return nx == ny == 1
