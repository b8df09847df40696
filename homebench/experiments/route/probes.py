"""Where a route memory points along and beside its route: probes, catchment, RIDF data.

Baddeley et al. (2012) judge a route memory by the direction it finds: on the route the most
familiar direction is the route's; beside it, it should still lead along the route or back to
it, out to some distance from it (the route's catchment). In a generated world the true route
is known, so this is measured directly (:class:`ProbeSpec`):

- **stations** every ``spacing_m`` metres along the true outbound path from home, and at each a
  **probe** at every lateral offset of ``offsets_m`` (metres, positive to the left of the way
  home; 0: on the route);
- at each probe the view at a seeded random heading (the method must find the direction from
  the view alone), the method's most familiar direction in the world frame and its
  unfamiliarity at every rotation (the RIDF: ``ridf[s]`` for the view rolled by s columns,
  the direction ``heading - s * 360 / n`` degrees);
- the truth: the direction of the way home along the route at the point of the true path
  nearest the probe. ``error_deg``: the absolute difference; ``approach``: whether the found
  direction also closes on the route (a positive component towards that nearest point; None
  on the route);
- **catchment** (:func:`catchment`): per distance from the route (both sides pooled), the median
  error of its probes; the catchment is the largest tested distance up to which every tested
  distance's median error is below ``threshold_deg`` (None when the smallest fails).

Probes in an obstacle or outside the scene are kept as rows with ``seen`` False and no estimate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, FiniteFloat

from homebench.data.synth.world import PoseError
from homebench.geometry import FloatArray, PanoramaGeometry, Pose, angle_diff, wrap_angle
from homebench.methods.base import is_flat
from homebench.methods.familiarity.route_memory import most_familiar
from homebench.views import View

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Path points closer than this (metres) are one point (frames that only turned).
SAME_POINT_M = 1e-9


class ProbeSpec(BaseModel):
    """Probes of a route memory's heading field: stations every ``spacing_m`` metres along the
    true route, ``offsets_m`` beside it (left of the way home positive), ``threshold_deg`` for
    the catchment."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    spacing_m: float = Field(0.5, gt=0)  # metres between stations along the true route
    # lateral offsets of each station's probes, metres (left of the way home positive; 0: on it)
    offsets_m: list[FiniteFloat] = Field(
        default_factory=lambda: [-1.0, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0], min_length=1
    )
    # the catchment: out to where every distance's median direction error stays below this
    threshold_deg: float = Field(45.0, gt=0, le=180)


@dataclass(frozen=True)
class Probe:
    """A place to probe: ``along_m`` (the station's distance from home along the path),
    ``offset_m``, the ``pose`` of its view, ``truth`` (the way home along the route at the
    nearest path point, rad, world frame) and ``nearest`` (that point, (2,) metres)."""

    along_m: float
    offset_m: float
    pose: Pose
    truth: float
    nearest: FloatArray


def path_points(outbound: NDArray[np.float64]) -> FloatArray:
    """The distinct positions (m, 2) of the outbound poses (n, 3) in order (frames that only
    turned on the spot add none)."""
    xy = np.asarray(outbound, dtype=np.float64)[:, :2]
    keep = np.r_[True, np.hypot(*np.diff(xy, axis=0).T) > SAME_POINT_M]
    return xy[keep]


def nearest_on_path(path: FloatArray, points: FloatArray) -> tuple[NDArray[np.intp], FloatArray]:
    """For each of ``points`` (p, 2): the index of the segment of ``path`` (m >= 2 points)
    nearest to it and the nearest point on it (p, 2)."""
    start, step = path[:-1], np.diff(path, axis=0)  # (k, 2)
    along = np.einsum("pkc,kc->pk", points[:, None, :] - start[None], step) / np.sum(step**2, 1)
    feet = start[None] + np.clip(along, 0.0, 1.0)[..., None] * step[None]  # (p, k, 2)
    segment = np.argmin(np.hypot(*(feet - points[:, None, :]).transpose(2, 0, 1)), axis=1)
    return segment, feet[np.arange(len(points)), segment]


def plan_probes(outbound: NDArray[np.float64], spec: ProbeSpec, seed: int) -> list[Probe]:
    """The probes of the outbound route (true poses (n, 3), home first), stations from home;
    view headings uniform in [-pi, pi) from ``seed``."""
    path = path_points(outbound)
    step = np.diff(path, axis=0)
    lengths = np.hypot(*step.T)
    ends = np.r_[0.0, np.cumsum(lengths)]
    homeward = np.arctan2(-step[:, 1], -step[:, 0])  # the way home along each segment
    rng = np.random.default_rng(seed)
    probes = []
    for along in np.arange(0.0, ends[-1] + SAME_POINT_M, spec.spacing_m):
        k = min(int(np.searchsorted(ends, along, side="right")) - 1, len(lengths) - 1)
        station = path[k] + (along - ends[k]) / lengths[k] * step[k]
        left = homeward[k] + math.pi / 2
        offsets = np.asarray(spec.offsets_m, dtype=np.float64)
        places = station + offsets[:, None] * np.array([math.cos(left), math.sin(left)])
        segments, feet = nearest_on_path(path, places)
        for offset, place, segment, foot in zip(offsets, places, segments, feet, strict=True):
            heading = float(rng.uniform(-math.pi, math.pi))
            pose = Pose(float(place[0]), float(place[1]), heading)
            probes.append(Probe(float(along), float(offset), pose, homeward[segment], foot))
    return probes


def probe_row(
    probe: Probe, image: NDArray[np.uint8] | None, method: Any, memory: Any, geometry: Any
) -> dict[str, Any]:
    """One probe's row: where, what the memory finds in ``image`` (None: not seen) and the
    error against the truth (degrees); ``ridf``: the unfamiliarity per column shift."""
    pose = probe.pose
    row: dict[str, Any] = {
        "along_m": probe.along_m,
        "offset_m": probe.offset_m,
        "x": pose.x,
        "y": pose.y,
        "heading_deg": math.degrees(pose.heading),
        "route_deg": math.degrees(probe.truth),
        "seen": image is not None,
        "direction_deg": None,
        "error_deg": None,
        "approach": None,
        "score": None,
        "ridf": None,
    }
    if image is None:
        return row
    features = method.describe(View(image, geometry))
    if is_flat(features):
        return row
    profile, diagnostics = method.scan(memory, features)
    estimate = most_familiar(profile, **diagnostics)
    direction = float(wrap_angle(pose.heading + estimate.angle))
    towards = probe.nearest - np.asarray(pose.xy)
    closes = float(np.dot([math.cos(direction), math.sin(direction)], towards)) > 0
    row |= {
        "direction_deg": math.degrees(direction),
        "error_deg": math.degrees(abs(float(angle_diff(direction, probe.truth)))),
        "approach": None if probe.offset_m == 0 else closes,
        "score": estimate.score,
        "ridf": profile.tolist(),
    }
    return row


def probe_route(
    probes: list[Probe],
    see: Callable[[Pose, int], NDArray[np.uint8]],
    method: Any,
    memory: Any,
    geometry: PanoramaGeometry,
) -> list[dict[str, Any]]:
    """Every probe's row (:func:`probe_row`); ``see``: the scene's camera (raises PoseError
    where it cannot show a pose), frames numbered in probe order."""
    rows = []
    for k, probe in enumerate(probes):
        try:
            image: NDArray[np.uint8] | None = see(probe.pose, k)
        except PoseError:
            image = None
        rows.append(probe_row(probe, image, method, memory, geometry))
    return rows


def catchment(
    rows: list[dict[str, Any]], threshold_deg: float
) -> tuple[float | None, list[dict[str, Any]]]:
    """The catchment (metres, or None) of probe ``rows`` and, per distance from the route (both
    sides pooled, ascending), its probes with an estimate, median error, share within
    ``threshold_deg`` and share approaching the route (None on it)."""
    table = []
    for distance in sorted({abs(row["offset_m"]) for row in rows}):
        mine = [r for r in rows if abs(r["offset_m"]) == distance and r["error_deg"] is not None]
        errors = np.array([r["error_deg"] for r in mine], dtype=np.float64)
        closing = [r["approach"] for r in mine if r["approach"] is not None]
        table.append(
            {
                "distance_m": distance,
                "probes": len(mine),
                "median_error_deg": float(np.median(errors)) if mine else None,
                "within_share": float(np.mean(errors < threshold_deg)) if mine else None,
                "approach_share": float(np.mean(closing)) if closing else None,
            }
        )
    reach = None
    for entry in table:
        median = entry["median_error_deg"]
        if median is None or median >= threshold_deg:
            break
        reach = entry["distance_m"]
    return reach, table


def ridf_curve(row: dict[str, Any]) -> tuple[FloatArray, FloatArray]:
    """A probe row's RIDF against the direction relative to the route's (degrees in
    [-180, 180), ascending) and its values."""
    values = np.asarray(row["ridf"], dtype=np.float64)
    shifts = np.arange(values.size)
    direction = row["heading_deg"] - shifts * 360.0 / values.size - row["route_deg"]
    relative = (direction + 180.0) % 360.0 - 180.0
    order = np.argsort(relative)
    return relative[order], values[order]


def ridf_figure(rows: list[dict[str, Any]], along_m: float, title: str = "") -> Figure:
    """The RIDFs of the probes of the station ``along_m`` metres from home, one curve per
    offset: unfamiliarity against the direction relative to the way home along the route."""
    from matplotlib.figure import Figure  # imported where needed: plotting is optional

    figure = Figure(figsize=(5.0, 3.2))
    axes = figure.add_subplot()
    for row in rows:
        if row["along_m"] == along_m and row["ridf"] is not None:
            axes.plot(*ridf_curve(row), label=f"{row['offset_m']:+g} m")
    axes.axvline(0.0, color="0.5", linewidth=0.8)
    axes.set_xlabel("direction relative to the route's way home [deg]")
    axes.set_ylabel("unfamiliarity")
    axes.set_title(title or f"RIDF {along_m:g} m from home")
    axes.legend(title="offset", fontsize="small")
    return figure


def probe_tables(records: list[dict[str, Any]]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """From trial ``records`` (those with probes): every probe (trial, method, then the row
    without its RIDF) and the catchment table per trial, method and distance."""
    probes, distances = [], []
    for record in records:
        head = {"trial": record["trial"], "method": record.get("method")}
        probes += [{**head, **_without_ridf(row)} for row in record.get("probes", [])]
        distances += [{**head, **entry} for entry in record.get("catchment", [])]
    return pd.DataFrame(probes), pd.DataFrame(distances)


def _without_ridf(row: dict[str, Any]) -> dict[str, Any]:
    return {key: value for key, value in row.items() if key != "ridf"}
