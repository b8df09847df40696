"""``homebench data check`` on posed images (a route, any posed folder): the headings' and the
images' conventions from the poses and the images.

- **Headings against travel** (:mod:`.travel`): on a route, the convention that turns the
  recorded headings into the direction of travel. Where they follow it (median residual at
  most 10 deg), the recorder faced the way it moved and this gives the headings' zero (and
  their sense, where they turn).
- **Homing between nearby images** (:func:`place_pairs`): each pair's true home direction
  comes from the two poses and the current image's heading, under each heading sense; the
  homed estimates under each column direction. The reading (sense x direction) with one
  constant turn that fits (:mod:`.readings`) gives the sense, the direction and, after the
  heading zero the travel gave, the azimuth zero (``zero_column``); where the headings do not
  follow travel the turn may as well be the headings' zero, the alternative. Then the
  horizon from the flow between the pairs, as on a grid.

Pairs: up to :data:`PAIRS` current images (drawn with a seed), each with a goal at least
:data:`NEAR` times the median spacing away: every other one the goal most off the route's line
within :data:`FAR_OFF` spacings (a route's pairs along its line tell no direction: a mirror
image maps straight ahead and behind to themselves), the others at random within
:data:`FAR`. Where a reading with the
other sense or direction fits as well, that convention is "not checked", never taken as right.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from homebench.data.check.checker import estimates, images_rim, with_horizon
from homebench.data.check.findings import (
    HEADINGS_KEY,
    HEADINGS_ZERO_KEY,
    Finding,
    KindCheck,
    compare,
)
from homebench.data.check.pairs import PlacePair
from homebench.data.check.readings import (
    MIN_HOMED,
    Choice,
    Reading,
    as_good,
    choose,
    fit_readings,
)
from homebench.data.check.travel import TravelFit, fit_travel, travel_directions
from homebench.data.posed import PosedDatabase
from homebench.errors import DataError
from homebench.geometry import (
    HeadingConvention,
    home_direction,
    nearest_spacing,
    other_direction,
    wrap_angle,
)

FloatArray = NDArray[np.float64]

#: Current images homed.
PAIRS = 100
#: A goal lies between these many median spacings from its current image (the goals chosen
#: off the route's line, up to ``FAR_OFF``).
NEAR, FAR, FAR_OFF = 2.0, 8.0, 20.0
#: Pairs whose flow places the horizon.
FLOW_PAIRS = 40
#: Largest difference (deg) between the stated heading zero and the travel's taken as agreement.
ZERO_TOLERANCE_DEG = 5.0


@dataclass(frozen=True)
class PosedCheck:
    """What ``data check`` found on posed images: the headings against travel (None: too
    few moving poses) and the findings on the images."""

    travel: TravelFit | None
    check: KindCheck

    @property
    def agrees(self) -> bool:
        return self.check.agrees


def check_posed(db: PosedDatabase, seed: int = 0) -> PosedCheck:
    """Check the headings' and the images' conventions of ``db`` against its poses and images
    (see the module docstring); DataError when too few pairs of images lie near each other."""
    recorded = db.recorded_heading_deg
    stated = db.headings
    travel = fit_travel(db.xy, recorded, stated.direction)
    pairs = place_pairs(db.xy, PAIRS, seed)
    if len(pairs) < MIN_HOMED:
        raise DataError(
            f"{db.root}: data check homes between images {NEAR:g} to {FAR_OFF:g} median "
            f"spacings apart and needs {MIN_HOMED} such pairs for a verdict; {db.layout()} "
            f"gives {len(pairs)}"
        )
    needed = sorted({ij for p in pairs for ij in (p.current, p.goal)})
    images = {ij: db.image(ij[0]) for ij in needed}
    manifest = db.camera
    start, rim = images_rim(manifest, images, seed)
    truths = _sense_truths(db, pairs, recorded, stated)
    fits = fit_readings(HEADINGS_KEY, truths, estimates(start, images, pairs), pairs)
    choice = choose(fits, Reading(HEADINGS_KEY, stated.direction, manifest.direction), None)
    follows = travel is not None and travel.follows
    zero_shift = math.radians(travel.convention.zero_deg - stated.zero_deg) if follows else 0.0
    reading = choice.reading or next(iter(fits))
    fitted = replace(start, direction=reading.direction).turned(
        float(wrap_angle(fits[reading].offset - zero_shift))
    )
    if choice.reading is not None:  # motions in the fitted frame: the travel's heading zero
        motions = truths[reading.value][:FLOW_PAIRS] - zero_shift
        fitted = with_horizon(fitted, images, pairs[:FLOW_PAIRS], motions)
    heading = None if follows else (HEADINGS_ZERO_KEY, stated.zero_deg)
    check = compare(db.kind, manifest, fitted, choice, next(iter(fits)), rim, heading)
    findings = _untold(check.findings, fits, choice)
    if choice.reading is None and follows and travel.sense_known:
        findings = [_travel_sense(stated, travel) if f.key == HEADINGS_KEY else f for f in findings]
    findings.insert(1, _heading_zero(stated, travel))
    return PosedCheck(travel, replace(check, findings=tuple(findings)))


def place_pairs(xy: FloatArray, n: int, seed: int = 0) -> list[PlacePair]:
    """Up to ``n`` pairs of the posed images at ``xy`` (n, 2) metres, addressed as places
    (k, 0): see the module docstring."""
    from scipy.spatial import cKDTree  # imported where needed: most commands need none

    spacing = nearest_spacing(xy)
    tree = cKDTree(xy)
    travel, _ = travel_directions(xy)
    rng = np.random.default_rng(seed)
    pairs = []
    for k in rng.permutation(len(xy)):
        off_line = len(pairs) % 2 == 0
        reach = (FAR_OFF if off_line else FAR) * spacing
        near = np.array([j for j in tree.query_ball_point(xy[k], reach) if j != k], np.int64)
        chord = xy[near] - xy[k] if near.size else np.zeros((0, 2))
        candidates = near[np.hypot(chord[:, 0], chord[:, 1]) >= NEAR * spacing]
        if candidates.size == 0:
            continue
        if off_line:
            d = xy[candidates] - xy[k]
            off = np.abs(np.sin(np.arctan2(d[:, 1], d[:, 0]) - travel[k]))
            goal = int(candidates[np.argmax(off)])
        else:
            goal = int(rng.choice(candidates))
        pairs.append(PlacePair((int(k), 0), (goal, 0), _way(xy[goal] - xy[k])))
        if len(pairs) == n:
            break
    return pairs


def _way(chord: FloatArray) -> str:
    """The axis and sign of the larger component of ``chord`` (2,): "+x", ..., "-y"."""
    axis = 0 if abs(chord[0]) >= abs(chord[1]) else 1
    return ("+" if chord[axis] >= 0 else "-") + "xy"[axis]


def _sense_truths(
    db: PosedDatabase,
    pairs: list[PlacePair],
    recorded: FloatArray,
    stated: HeadingConvention,
) -> dict[str, FloatArray]:
    """Each pair's true home direction (radians, (n_pairs,)) with the headings read with the
    stated zero and each sense, the stated first."""
    current = np.array([p.current[0] for p in pairs])
    goal = np.array([p.goal[0] for p in pairs])
    truths = {}
    for sense in (stated.direction, other_direction(stated.direction)):
        heading = HeadingConvention(stated.zero_deg, sense).to_world_deg(recorded[current])
        truths[sense] = home_direction(db.xy[current], db.xy[goal], np.radians(heading))
    return truths


def _heading_zero(stated: HeadingConvention, travel: TravelFit | None) -> Finding:
    """The headings' zero, from the direction of travel where the headings follow it."""
    key, given = HEADINGS_ZERO_KEY, f"{stated.zero_deg:g}"
    if travel is None or not travel.follows:
        why = (
            "too few moving poses"
            if travel is None
            else f"the headings do not follow the direction of travel (best median "
            f"{travel.median_deg:.1f} deg off)"
        )
        return Finding("heading zero", key, given, "-", None, f"not checked: {why}")
    found = travel.convention.zero_deg
    off = float(np.degrees(wrap_angle(np.radians(found - stated.zero_deg))))
    return Finding(
        "heading zero", key, given, f"{found:g}", abs(off) <= ZERO_TOLERANCE_DEG,
        f"from the direction of travel: {off:+.1f} deg apart (tolerance "
        f"{ZERO_TOLERANCE_DEG:g})",
    )  # fmt: skip


def _travel_sense(stated: HeadingConvention, travel: TravelFit) -> Finding:
    """The headings' sense from the direction of travel, where the images tell none."""
    found = travel.convention.direction
    return Finding(
        "heading sense", HEADINGS_KEY, stated.direction, found, found == stated.direction,
        "from the direction of travel",
    )  # fmt: skip


def _untold(
    findings: tuple[Finding, ...], fits: dict[Reading, object], choice: Choice
) -> list[Finding]:
    """``findings`` with the sense and the direction "not checked" where a reading with the
    other one fits as well (pairs along one line, headings that do not turn)."""
    good = as_good(fits)  # type: ignore[arg-type]
    chosen = choice.reading
    if chosen is None:
        return list(findings)
    other_sense = any(r.value != chosen.value for r in good)
    other_direction_ = any(r.direction != chosen.direction for r in good)
    untold = {"heading sense": other_sense, "direction": other_direction_}
    return [
        replace(
            f,
            images="-",
            agrees=None,
            detail="not checked: a reading with the other one fits as well (pairs along one "
            "line, or headings that do not turn)",
        )
        if untold.get(f.what)
        else f
        for f in findings
    ]
