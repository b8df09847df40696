"""The schema of a closed-loop trial's file (:mod:`homebench.experiments.trials`): its summary
(a row of ``trials.csv``) and its trajectory, as the tables and the report read them."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from homebench.experiments.closed_loop.loop import Outcome
from homebench.experiments.trials import Poses, TrialRecord


class ClosedLoopSummary(BaseModel):
    """A trial's row (see :func:`~homebench.experiments.closed_loop.experiment.run_trial`)."""

    model_config = ConfigDict(extra="allow", strict=True)

    style: str
    method: str
    goal: int
    goal_x: float
    goal_y: float
    start: int
    start_x: float
    start_y: float
    start_heading_deg: float
    cell_i: int
    cell_j: int
    cell_area_m2: float
    start_distance_m: float
    outcome: Outcome
    success: bool
    final_distance_m: float
    path_m: float
    path_ratio: float
    steps: int
    no_estimates: int
    time_s: float
    see_s_per_step: float
    home_s_per_step: float


class ClosedLoopRecord(TrialRecord):
    """A closed-loop trial's file: its ``summary`` and true ``trajectory`` (n, 3)."""

    summary: ClosedLoopSummary
    trajectory: Poses = Field(min_length=1)
