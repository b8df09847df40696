"""Route following by familiarity (perfect-memory, infomax): learn the outbound route, follow it.

**Training.** The robot keeps the view of every outbound frame (the paper's agent learnt a
view at every step of its route). Homing runs the route backwards, so each view is turned by
half a turn before the method learns it: a panorama holds every heading, and the view turned
by pi is the one the robot would have seen there facing home along the route (the paper's
agent learnt its views facing the way it later travelled). The method learns them in the
order they were taken, as a robot learning on its way out would
(:meth:`~homebench.experiments.memory.MemoryGuide.trained`; order matters to Infomax).

**Following.** At each step the robot takes its view, the method gives the most familiar
direction (``follow``), and the robot turns by at most the turn limit and steps, as the
pairwise robot does (:func:`~.pairwise.drive_leg`; no direction: straight on,
``max_no_estimate`` in a row: ``lost``). No view is a target on the way; the run is one leg
whose target is home.

**Arrival** (:class:`~.pairwise.Arrival`, on the home view, frame 0 as taken): ``minimum``
watches the view distance to the home view, but only once the odometry puts the robot within
``near_home_m`` of home (far from home the view distance to the home view has no meaning for
progress; a familiarity method has no intermediate targets to tell it). ``oracle``: within
``radius_m`` of home. Then, as the pairwise robot on its home leg, back to the best view
(``return_to_best``) and a turn by the method's rotation estimate against the home view
(``align``: the method as a one-view compass). The run gives up after ``budget_factor`` times
the outbound frames.
"""

from __future__ import annotations

import math

from pydantic import Field

from homebench.experiments.memory import MemoryGuide
from homebench.experiments.robot import MotionLimits, Robot
from homebench.experiments.route.pairwise import (
    FollowParams,
    LegRun,
    Look,
    PairwiseHoming,
    Target,
    drive_leg,
    settle,
    take_view,
)
from homebench.experiments.route.probes import ProbeSpec


class FamiliarityParams(FollowParams):
    """Route following with a route-learning method: the follower's parameters
    (:class:`~.pairwise.FollowParams`), ``near_home_m`` (odometry distance from home within
    which arrival is watched), ``budget_factor`` (steps allowed, times the outbound frames) and
    the ``probes`` of the heading field (:class:`~.probes.ProbeSpec`; None: none)."""

    near_home_m: float = Field(1.0, gt=0)  # minimum arrival is watched this near home (odometry)
    budget_factor: float = Field(3.0, ge=1)  # steps allowed, times the outbound route's frames
    probes: ProbeSpec | None = None  # probes of the memory's heading field; None: none


def follow_home(
    robot: Robot,
    guide: MemoryGuide,
    home: Target,
    look: Look,
    limits: MotionLimits,
    params: FamiliarityParams,
    outbound_frames: int,
    home_xy: tuple[float, float],
) -> PairwiseHoming:
    """Follow ``guide``'s memory from the robot's pose to ``home`` (its homer: the method as a
    compass on the home view); ``home_xy``: home as the odometry knows it (metres)."""
    result = PairwiseHoming([robot.pose])
    leg = LegRun(home, robot)
    max_steps = math.ceil(params.budget_factor * outbound_frames)

    def near(robot: Robot) -> bool:
        oracle = params.arrival.criterion == "oracle"
        return oracle or math.dist(robot.odometry.xy, home_xy) <= params.near_home_m

    image = take_view(look, robot, result)
    status, _ = drive_leg(
        robot, leg, guide.estimate, look, limits, params, max_steps, result, image, near
    )
    if status == "reached":
        settle(robot, leg, look, limits, params, result)
    result.legs.append(leg.result(status, robot))
    return result
