"""The schema of a route trial's file (:mod:`homebench.experiments.trials`): its summary (a row
of ``routes.csv``) and the poses, targets and probes the tables and the report read. Numbers
a trial left undefined are null (:func:`~homebench.experiments.route.experiment.run_trial`)."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

from homebench.experiments.trials import Poses, TrialRecord


class RouteSummary(BaseModel):
    """A job's row: the trial, the drive, visual and odometry homing (the columns every
    reader needs; the others typed where present)."""

    model_config = ConfigDict(extra="allow", strict=True)

    trial: str
    route: str
    length_m: float
    driven_m: float
    frames: int
    features: int | None
    n_intermediate: int
    visual_status: str
    visual_error_m: float
    visual_heading_error_deg: float | None
    odometry_error_m: float | None
    odometry_heading_error_deg: float | None
    odometry_drift_at_end_m: float | None
    method: str | None = None
    displacement_m: float | None = None
    features_home: int | None = None
    min_shared: int | None = None
    snapshots: int | None = None
    visual_steps: int | None = None
    visual_path_m: float | None = None
    legs: int | None = None
    probe_error_on_route_deg: float | None = None
    catchment_m: float | None = None


class ProbeRow(BaseModel):
    """A probe of a route-learning method's heading field
    (:func:`~homebench.experiments.route.probes.probe_row`)."""

    model_config = ConfigDict(extra="allow", strict=True)

    along_m: float
    offset_m: float
    heading_deg: float
    route_deg: float
    error_deg: float | None
    approach: bool | None
    ridf: list[float] | None


class CatchmentRow(BaseModel):
    """The probes at one distance from the route
    (:func:`~homebench.experiments.route.probes.catchment`)."""

    model_config = ConfigDict(extra="allow", strict=True)

    distance_m: float
    median_error_deg: float | None


class RouteRecord(TrialRecord):
    """A route job's file: its ``summary``, true poses (n, 3) of the drive (``outbound``),
    the visual homing and the odometry baseline, the ``intermediate`` targets (frames), and
    a route-learning method's ``probes`` and ``catchment`` rows."""

    trial: str
    method: str | None = None
    summary: RouteSummary
    outbound: Annotated[Poses, Field(min_length=1)]
    homing: Annotated[Poses, Field(min_length=1)]
    odometry: Annotated[Poses, Field(min_length=1)]
    intermediate: list[int]
    probes: list[ProbeRow] = []
    catchment: list[CatchmentRow] = []
