"""``data check``'s report as text."""

from __future__ import annotations

import math

from homebench.data.check.azimuth import AzimuthFit
from homebench.data.check.findings import KindCheck
from homebench.data.check.posed import PosedCheck
from homebench.data.check.readings import MAX_MEAN_AE_DEG, Reading

VERDICTS = {True: "agrees", False: "DISAGREES", None: "-"}


def report_lines(
    checks: list[KindCheck], method: str, pairs: str = "pairs one step apart"
) -> list[str]:
    """The check as text: per kind, homing between ``pairs`` under each reading of the
    database (a grid's order, a route's heading sense; the direction) and a table of the
    findings; then the verdict, with the corrections to make."""
    lines = []
    for check in checks:
        as_given = next(iter(check.fits.values()))
        lines += [
            f"{check.kind} images: homing ({method}, {as_given.n_pairs} {pairs})",
            f"  as stated: mean AE {math.degrees(as_given.mean_ae_as_is):.1f} deg",
        ]
        lines += [_fit_line(reading, fit) for reading, fit in check.fits.items()]
        for f in check.findings:
            lines.append(
                f"  {f.what:<15} manifest {f.manifest:<16} images {f.images:<16} "
                f"{VERDICTS[f.agrees]:<9} {f.detail}".rstrip()
            )
    wrong = [f for check in checks for f in check.findings if f.agrees is False]
    if not wrong:
        return [*lines, "the manifest agrees with the images"]
    return [*lines, "the manifest disagrees with the images; correct it:"] + [
        f"  {f.fix()}" for f in wrong
    ]


def posed_report_lines(result: PosedCheck, method: str) -> list[str]:
    """The check of posed images as text: the headings against the direction of travel, then
    as :func:`report_lines`."""
    travel = result.travel
    if travel is None:
        head = ["headings against travel: too few moving poses to compare"]
    else:
        convention = travel.convention
        sense = "" if travel.sense_known else " (the headings do not turn: sense as stated)"
        how = "follow it: the recorder faced the way it moved" if travel.follows else (
            "do not follow it: the camera did not face the way it moved, or the headings are "
            "not the camera's"
        )  # fmt: skip
        head = [
            f"headings against the direction of travel ({travel.n_steps} poses): closest as "
            f"{{zero_deg: {convention.zero_deg:g}, direction: {convention.direction}}}{sense}, "
            f"median {travel.median_deg:.1f} deg off; they {how}"
        ]
    return head + report_lines([result.check], method, "pairs of nearby images")


def _fit_line(reading: Reading, fit: AzimuthFit) -> str:
    """How homing went under ``reading``."""
    mean_ae = math.degrees(fit.mean_ae)
    how = (
        f"with the azimuths turned by {math.degrees(fit.offset):+.1f} +- "
        f"{math.degrees(fit.offset_se):.1f} deg"
        if mean_ae <= MAX_MEAN_AE_DEG
        else "at best: no turn of the azimuths fits"
    )
    where = f"{reading.key} {reading.value:<12} direction {reading.direction:<3}"
    return f"  {where}: {fit.n_homed} homed, mean AE {mean_ae:.1f} deg {how}"
