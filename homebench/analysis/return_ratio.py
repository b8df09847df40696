"""Simulated homing on a home-vector field: the return ratio (seed 001, eq. 13) and Möller's
discrete catchment-area variant.

Conventions shared by both: every start (by default every grid position) is one trial, the goal
itself included, which succeeds at once; the ratio is the share of successful trials. A position
without an estimate (NaN in the field) ends any trial that needs its direction: in failure
(Möller's variant always; the return ratio by default), or, for the return ratio with
``no_estimate="arrived"``, as an arrival when the position is one of the goal's grid neighbours
(:data:`NO_ESTIMATE_READINGS`). All lengths of the return ratio (step, success radius, travel)
are in grid units: multiples of the grid spacing.

What seed 001 says (section 4.3, the step procedure under eq. 13): the robot "moves a step
according to the corresponding beta_h(x,y)" of the nearest grid position, and a trial ends only
when "the robot arrives at the goal position H" (success: "within a given distance threshold of
H ... set to 0.5", no unit named; homebench reads it in the unit of the step rh = 0.8, "the
ratio between the actual step length of the robot and the sampling interval of the images":
grid units) or when "the robot travels a
distance longer than half of the perimeter of the capture grid" (failure). It presumes an angle
at every position ("homing vectors, which have been pre-computed") and is silent on a position
without one: a robot there can neither step nor arrive. ``fail`` (the default, homebench's
reading since the start) ends that walk as a failure: a method gains nothing by abstaining.

On a grid with holes (:class:`~homebench.geometry.HoledGrid`: positions without an image) the
trials start at the positions present only. The return-ratio robot steers by the nearest
position present (a hole has no image to read); Möller's variant, which moves from node to
node, fails on stepping onto a hole, as onto a position without an estimate. Neither number is
then strictly comparable with a full grid's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from homebench.analysis.metrics import BoolArray, HomeField
from homebench.config import ReturnRatioConfig, RRNoEstimate
from homebench.geometry import FloatArray, Grid, world_direction

#: The readings of ``no_estimate`` (:data:`homebench.config.RRNoEstimate` says what each does).
NO_ESTIMATE_READINGS: tuple[str, ...] = get_args(RRNoEstimate)

# 8-neighbour offsets (di, dj) by octant k: the world direction k * pi/4 (i along x, j along y).
_OCTANT_STEPS = np.array([(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)])


@dataclass(frozen=True, eq=False)
class ReturnRatioResult:
    """Outcome of :func:`return_ratio`; per-position arrays have the grid's shape (nx, ny).

    ``rr``: share of the started trials that succeed. ``success``: False where no trial started.
    ``path_length``: distance travelled in grid units (NaN where no trial started).
    ``no_estimate``: the walk ended on a position without an estimate (a failure, or with
    ``no_estimate="arrived"`` next to the goal a success). ``starts``: the
    started grid indices, shape (n, 2), in the order of ``steps`` (steps taken per start,
    shape (n,)) and of ``trajectories``: world positions in metres after each step, shape
    (n, n_steps + 1, 2), a finished robot staying put (None unless asked for).
    """

    rr: float
    success: BoolArray
    started: BoolArray
    path_length: FloatArray
    no_estimate: BoolArray
    starts: NDArray[np.int64]
    steps: NDArray[np.int64]
    trajectories: FloatArray | None

    def outcomes(self) -> dict[str, NDArray]:
        """One entry per start, in the order of ``starts``, each of shape (n,): ``start_i``,
        ``start_j``, ``steps``, ``success``, ``path_length`` (grid units) and
        ``no_estimate`` (ended on a position without an estimate); a table's columns."""
        i, j = self.starts[:, 0], self.starts[:, 1]
        return {
            "start_i": i,
            "start_j": j,
            "steps": self.steps,
            "success": self.success[i, j],
            "path_length": self.path_length[i, j],
            "no_estimate": self.no_estimate[i, j],
        }


@dataclass(frozen=True, eq=False)
class CatchmentResult:
    """Outcome of :func:`catchment`: ``ratio`` (share of grid nodes that reach the goal) and
    ``success`` (nx, ny) bool."""

    ratio: float
    success: BoolArray


def return_ratio(
    field: HomeField,
    rh: float = 0.8,
    success_radius: float = 0.5,
    max_travel: float | None = None,
    starts: ArrayLike | None = None,
    keep_trajectories: bool = False,
    no_estimate: RRNoEstimate = "fail",
) -> ReturnRatioResult:
    """Return ratio of a home-vector field (eq. 13, the step procedure of seed 001, 4.3).

    A dummy robot starts at each of ``starts`` (grid indices, shape (n, 2); default every grid
    position present) and, all robots together, repeats: succeed if within ``success_radius``
    of the goal (so a start within it, the goal itself always, succeeds with no travel); fail
    once it has travelled more than ``max_travel``; otherwise take one step of ``rh`` along
    the world-frame direction of the grid position (present) nearest to it. All lengths are
    in grid units (multiples of the grid spacing); ``max_travel`` defaults to half the grid's
    perimeter. A robot that leaves the grid keeps moving, steered by the nearest position
    clipped to the grid (the paper says nothing else). A robot whose nearest position has no
    estimate stops there: it fails (``no_estimate="fail"``, the default) or, with
    ``"arrived"``, succeeds when that position is one of the goal's 8 grid neighbours
    (:data:`~homebench.config.RRNoEstimate`; the module's docstring says why the paper leaves
    this open). The home direction at the goal itself is undefined, so the field's entry there
    is never used: a robot in the goal's cell (nearest position = the goal) steers straight at
    the goal, i.e. it has arrived at the grid's resolution and only ``success_radius`` decides
    how close it must get.
    """
    grid = field.grid
    if max_travel is None:
        max_travel = grid.perimeter / (2.0 * grid.spacing)
    if not (rh > 0 and success_radius >= 0 and max_travel >= 0):
        raise ValueError(
            f"need rh > 0, success_radius >= 0, max_travel >= 0; got {rh}, "
            f"{success_radius}, {max_travel}"
        )
    if no_estimate not in NO_ESTIMATE_READINGS:
        raise ValueError(f"no_estimate must be one of {NO_ESTIMATE_READINGS}, got {no_estimate!r}")
    started = _start_mask(grid, starts)
    start_ij = np.argwhere(started)
    n = len(start_ij)
    pos = grid.position(start_ij[:, 0], start_ij[:, 1])
    goal = field.goal_xy
    n_steps = np.zeros(n, dtype=np.int64)
    active = np.ones(n, dtype=bool)
    success = np.zeros(n, dtype=bool)
    ended = np.zeros(n, dtype=bool)  # on a position without an estimate
    path = [pos.copy()] if keep_trajectories else []

    while active.any():
        arrived = active & (np.hypot(*(pos - goal).T) <= success_radius * grid.spacing)
        success |= arrived
        active &= ~arrived & ~(n_steps * rh > max_travel)
        idx = np.flatnonzero(active)
        ij = grid.nearest_index(pos[idx])
        beta = field.angles[ij[:, 0], ij[:, 1]]
        in_goal_cell = np.all(ij == field.goal, axis=-1)
        beta[in_goal_cell] = world_direction(pos[idx[in_goal_cell]], goal)
        lost = np.isnan(beta)
        ended[idx[lost]] = True
        active[idx[lost]] = False
        if no_estimate == "arrived":
            near = np.all(np.abs(ij[lost] - np.asarray(field.goal)) <= 1, axis=-1)
            success[idx[lost][near]] = True
        idx, beta = idx[~lost], beta[~lost]
        if idx.size:
            pos[idx] += rh * grid.spacing * np.stack([np.cos(beta), np.sin(beta)], axis=-1)
            n_steps[idx] += 1
            if keep_trajectories:
                path.append(pos.copy())

    return ReturnRatioResult(
        rr=float(np.mean(success)),
        success=_to_grid(grid, start_ij, success, False),
        started=started,
        path_length=_to_grid(grid, start_ij, n_steps * rh, np.nan),
        no_estimate=_to_grid(grid, start_ij, ended, False),
        starts=start_ij,
        steps=n_steps,
        trajectories=np.stack(path, axis=1) if keep_trajectories else None,
    )


def catchment(field: HomeField) -> CatchmentResult:
    """Möller's catchment-area variant: follow the field from node to node.

    From each node the robot moves to the 8-neighbour whose direction is closest to the node's
    home angle (a tie half-way between two neighbours goes to the axis-aligned one). It
    succeeds on reaching the goal node (the goal itself succeeds at once) and fails on stepping
    off the grid, on a node without an estimate or a missing one, or on revisiting a node (a
    cycle). The ratio is over the nodes present.
    """
    grid = field.grid
    nx, ny = grid.shape
    n = nx * ny  # nodes, those missing among them
    sink = n  # absorbing failure state
    valid = ~np.isnan(field.angles) & grid.present()
    octant = np.rint(np.where(valid, field.angles, 0.0) / (np.pi / 4)).astype(np.int64) % 8
    ii, jj = np.indices(grid.shape)
    ni = ii + _OCTANT_STEPS[octant, 0]
    nj = jj + _OCTANT_STEPS[octant, 1]
    inside = valid & (ni >= 0) & (ni < nx) & (nj >= 0) & (nj < ny)
    goal = field.goal[0] * ny + field.goal[1]
    nxt = np.full(n + 1, sink, dtype=np.int64)
    nxt[:n] = np.where(inside, ni * ny + nj, sink).ravel()
    nxt[goal] = goal
    # Pointer doubling: after m rounds nxt is the 2**m-step map; a path to the goal visits
    # fewer than n nodes, and a cycle or the sink never reaches it.
    reach = 1
    while reach < n:
        nxt = nxt[nxt]
        reach *= 2
    success = (nxt[:n] == goal).reshape(grid.shape)
    return CatchmentResult(ratio=float(np.mean(success[grid.present()])), success=success)


def _start_mask(grid: Grid, starts: ArrayLike | None) -> BoolArray:
    """(nx, ny) mask of the start positions; every position present when ``starts`` is
    None."""
    if starts is None:
        return grid.present()
    ij = np.asarray(starts, dtype=np.int64).reshape(-1, 2)
    if ij.size == 0 or not all(grid.contains(i, j) for i, j in ij.tolist()):
        raise ValueError(f"starts must be grid indices present in {grid.shape}, got {ij.tolist()}")
    mask = np.zeros(grid.shape, dtype=bool)
    mask[ij[:, 0], ij[:, 1]] = True
    return mask


def _to_grid(grid: Grid, ij: NDArray[np.int64], values: NDArray, fill: float | bool) -> NDArray:
    """Scatter per-start ``values`` (n,) to a grid-shaped array filled with ``fill``."""
    out = np.full(grid.shape, fill, dtype=values.dtype)
    out[ij[:, 0], ij[:, 1]] = values
    return out


def configured_return_ratio(
    field: HomeField, config: ReturnRatioConfig, keep_trajectories: bool = False
) -> ReturnRatioResult:
    """:func:`return_ratio` of ``field`` with a run's settings (``metrics.return_ratio``)."""
    return return_ratio(
        field,
        config.rh,
        config.success_radius,
        config.max_travel,
        keep_trajectories=keep_trajectories,
        no_estimate=config.no_estimate,
    )
