"""``data check``'s report as text."""

from __future__ import annotations

import math

from homebench.data.check.azimuth import AzimuthFit
from homebench.data.check.findings import MAX_MEAN_AE_DEG, KindCheck

VERDICTS = {True: "agrees", False: "DISAGREES", None: "-"}


def report_lines(checks: list[KindCheck], method: str) -> list[str]:
    """The check as text: per kind, neighbour homing under each direction and a table of the
    findings; then the verdict, with the corrections to make."""
    lines = []
    for check in checks:
        as_given = next(iter(check.fits.values()))
        lines += [
            f"{check.kind} images: neighbour homing ({method}, {as_given.n_pairs} pairs one "
            "step apart)",
            "  with the manifest's direction and zero: mean AE "
            f"{math.degrees(as_given.mean_ae_as_is):.1f} deg",
        ]
        lines += [_fit_line(direction, fit) for direction, fit in check.fits.items()]
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


def _fit_line(direction: str, fit: AzimuthFit) -> str:
    """How homing went with azimuths growing in ``direction``."""
    mean_ae = math.degrees(fit.mean_ae)
    how = (
        f"with the azimuths turned by {math.degrees(fit.offset):+.1f} +- "
        f"{math.degrees(fit.offset_se):.1f} deg"
        if mean_ae <= MAX_MEAN_AE_DEG
        else "at best: no turn of the azimuths fits"
    )
    return f"  direction {direction:<3}: {fit.n_homed} homed, mean AE {mean_ae:.1f} deg {how}"
