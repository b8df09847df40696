"""What ``data check`` found: the manifest's conventions beside the images', key by key."""

from __future__ import annotations

import math
from dataclasses import dataclass

from homebench.data.check.azimuth import AzimuthFit
from homebench.data.check.readings import Choice, Reading
from homebench.data.check.rim import Circle
from homebench.geometry import CatadioptricGeometry, PanoramaGeometry, wrap_angle
from homebench.views import ImageKind

Model = PanoramaGeometry | CatadioptricGeometry

#: Largest azimuth offset (deg) taken as agreement (see the package docstring for the errors
#: measured with right manifests).
OFFSET_TOLERANCE_DEG = 2.0
#: ... or this many standard errors of the offset, where the ways of homing disagree more.
OFFSET_SE_FACTOR = 3.0
#: Largest distance (pixels) between the manifest's centre and the rim's taken as agreement.
CENTRE_TOLERANCE_PX = 2.0
#: Largest horizon error (deg of elevation) taken as agreement.
HORIZON_TOLERANCE_DEG = 2.0
#: The key (a manifest's, homebench.yaml's) of the order of a grid's labels ...
ORDER_KEY = "grid.order"
#: ... and (homebench.yaml's) of the way recorded headings grow and where their zero points.
HEADINGS_KEY = "headings.direction"
HEADINGS_ZERO_KEY = "headings.zero_deg"


@dataclass(frozen=True)
class Finding:
    """One convention: ``key`` (the manifest's key path), the manifest's and the images'
    value as text, whether they agree (None: not checked, ``detail`` says why) and, where
    no new value can be given, ``advice``; ``alternative``: another correction as good."""

    what: str
    key: str
    manifest: str
    images: str
    agrees: bool | None
    detail: str = ""
    advice: str | None = None
    alternative: str | None = None

    def fix(self) -> str:
        """The correction to make (or its ``alternative``)."""
        if self.advice is not None:
            return self.advice
        fix = f"set {self.key}: {self.images} (manifest: {self.manifest})"
        return f"{fix}, or {self.alternative}" if self.alternative else fix


@dataclass(frozen=True)
class KindCheck:
    """The findings on one image kind, and neighbour homing under each reading of the grid
    (``fits``, the stated reading's first)."""

    kind: ImageKind
    findings: tuple[Finding, ...]
    fits: dict[Reading, AzimuthFit]

    @property
    def agrees(self) -> bool:
        return all(f.agrees is not False for f in self.findings)


def compare(
    kind: ImageKind,
    manifest: Model,
    fitted: Model,
    choice: Choice,
    stated: Reading,
    rim: Circle | None,
    heading: tuple[str, float] | None,
) -> KindCheck:
    """The findings of ``kind``: the ``manifest``'s camera model and the ``stated`` reading of
    the database against the ``fitted`` model and the reading the images support
    (``choice``): the images' centre, the grid's order (a route's heading sense), the
    direction, azimuth zero and horizon. ``heading``: the key and stated value (deg) of a
    heading that turns every image alike, the alternative to a new azimuth zero (None: none,
    as where a manifest gives headings per position)."""
    known = choice.reading is not None
    fit = choice.fits[choice.reading or stated]
    findings = [_layout(stated, choice, manifest)] if len(choice.fits) > 2 else []
    findings += [
        _direction(manifest, fitted, choice),
        _zero(manifest, fitted, fit, known, heading),
        _horizon(manifest, fitted, known),
    ]
    if isinstance(manifest, CatadioptricGeometry):
        findings.insert(0, _centre(manifest, rim))
    return KindCheck(kind, tuple(findings), choice.fits)


def _key(manifest: Model, name: str) -> str:
    section = (
        "raw.catadioptric" if isinstance(manifest, CatadioptricGeometry) else "unfolded.panorama"
    )
    return f"images.{section}.{name}"


def _centre(manifest: CatadioptricGeometry, rim: Circle | None) -> Finding:
    key, stated = _key(manifest, "centre"), _numbers(manifest.centre)
    if rim is None:
        return Finding("centre", key, stated, "-", None, "not checked: no mirror rim found")
    off = math.dist(manifest.centre, rim.centre)
    return Finding(
        "centre", key, stated, _numbers(rim.centre), off <= CENTRE_TOLERANCE_PX,
        f"mirror rim of radius {rim.radius:.1f} px; {off:.1f} px apart "
        f"(tolerance {CENTRE_TOLERANCE_PX:g})",
    )  # fmt: skip


#: What each key of a reading is, in the findings.
LAYOUT = {ORDER_KEY: "grid order", HEADINGS_KEY: "heading sense"}


def _layout(stated: Reading, choice: Choice, manifest: Model) -> Finding:
    """Where the poses put the images: a grid's order (which position each label was taken
    at), a route's heading sense."""
    what = LAYOUT[stated.key]
    if choice.reading is None:
        return Finding(what, stated.key, stated.value, "-", None, "not checked: no fit")
    found = choice.reading.value
    alternative = choice.alternative
    other = (
        f"{_key(manifest, 'direction')}: {alternative.direction}"
        if alternative is not None and found != stated.value
        else None
    )
    detail = "fits as well as mirrored columns (see data/check/readings.py)" if other else ""
    agrees = found == stated.value
    return Finding(what, stated.key, stated.value, found, agrees, detail, None, other)


def _direction(manifest: Model, fitted: Model, choice: Choice) -> Finding:
    key = _key(manifest, "direction")
    if choice.reading is None:
        return Finding(
            "direction", key, manifest.direction, "undetermined", False,
            advice=f"{key}: the images tell no direction (neighbour homing fits no reading "
            "well); check the elevation range or radial profile, and that each file is the "
            "grid position its name says",
        )  # fmt: skip
    alternative = choice.alternative
    other = (
        f"{alternative.key}: {alternative.value}"
        if alternative is not None and fitted.direction != manifest.direction
        else None
    )
    agrees = manifest.direction == fitted.direction
    detail = "fits as well as another grid order (see data/check/readings.py)" if other else ""
    return Finding(
        "direction", key, manifest.direction, fitted.direction, agrees, detail, None, other
    )


def _zero(
    manifest: Model,
    fitted: Model,
    fit: AzimuthFit,
    known: bool,
    heading: tuple[str, float] | None,
) -> Finding:
    """The azimuth zero (``fit``: of the reading found): the zero column of a panorama, the
    zero angle of a raw image; where the direction is right and ``heading`` (key, degrees)
    turns every image alike, turning it instead is the alternative."""
    tolerance = max(OFFSET_TOLERANCE_DEG, OFFSET_SE_FACTOR * math.degrees(fit.offset_se))
    if isinstance(manifest, CatadioptricGeometry):
        assert isinstance(fitted, CatadioptricGeometry)
        what, key = "zero angle", _key(manifest, "zero_angle_deg")
        stated, found = math.degrees(manifest.zero_angle), math.degrees(fitted.zero_angle)
        offset = float(math.degrees(wrap_angle(fitted.zero_angle - manifest.zero_angle)))
    else:
        assert isinstance(fitted, PanoramaGeometry)
        what, key = "zero column", _key(manifest, "zero_column")
        stated, found = manifest.zero_column, round(fitted.zero_column, 1) % manifest.width
        offset = float(math.degrees(wrap_angle((found - stated) * manifest.column_step)))
    if not known:
        return Finding(what, key, f"{stated:.1f}", "-", None, "not checked: no direction")
    alternative = None
    if heading is not None and manifest.direction == fitted.direction:
        heading_key, stated_heading = heading
        turned = round(stated_heading + math.degrees(fit.offset), 1) % 360.0
        alternative = f"{heading_key}: {turned:.1f} (now: {stated_heading:.1f})"
    return Finding(
        what, key, f"{stated:.1f}", f"{found:.1f}", abs(offset) <= tolerance,
        f"{_signed(offset)} deg apart (tolerance {tolerance:.1f})", alternative=alternative,
    )  # fmt: skip


def _horizon(manifest: Model, fitted: Model, known: bool) -> Finding:
    """The horizon: the elevations of a raw image's radial profile, of a panorama's edges."""
    if isinstance(manifest, CatadioptricGeometry):
        assert isinstance(fitted, CatadioptricGeometry)
        key = _key(manifest, "elevations_deg")
        stated, found = _degrees(manifest.elevations), _degrees(fitted.elevations)
        where = f"radius {fitted.horizon_radius:.1f} px (manifest: {manifest.horizon_radius:.1f})"
        error = math.degrees(float(manifest.radius_to_elevation(fitted.horizon_radius)))
    else:
        assert isinstance(fitted, PanoramaGeometry)
        key = _key(manifest, "elevation_top_deg, elevation_bottom_deg")
        stated = _degrees((manifest.elevation_top, manifest.elevation_bottom))[1:-1]
        found = _degrees((fitted.elevation_top, fitted.elevation_bottom))[1:-1]
        where = f"row {fitted.horizon_row:.1f} (manifest: {manifest.horizon_row:.1f})"
        error = math.degrees(fitted.elevation_top - manifest.elevation_top)
    if not known:
        return Finding("horizon", key, stated, "-", None, "not checked: no direction")
    return Finding(
        "horizon", key, stated, found, abs(error) <= HORIZON_TOLERANCE_DEG,
        f"at {where}, {_signed(error)} deg of elevation (tolerance {HORIZON_TOLERANCE_DEG:g})",
    )  # fmt: skip


def _signed(value: float) -> str:
    """``value`` with its sign, one decimal, no "-0.0"."""
    return f"{round(value, 1) + 0.0:+.1f}"


def _numbers(values: tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{v:.1f}" for v in values) + "]"


def _degrees(values: tuple[float, ...]) -> str:
    return _numbers(tuple(math.degrees(v) for v in values))
