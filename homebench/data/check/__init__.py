"""``homebench data check``: a database's conventions estimated from its images, held against
its manifest.

What is estimated, how, and how well. Measured on five generated 10 x 17 sets
(``synth-original``, ``-lab-``, ``-corridor-``, ``-outdoor-original``, ``synth-twilight``),
each with its right manifest and with one planted error at a time: either kind's direction
mirrored, the zero column 90 columns off, the raw zero angle 37 deg off, the mirror centre
(5, -3) px off, the horizon 4 deg (panoramas) or 5 deg (raw) off. In all 40 cases the
planted error, and nothing else, was found; every right manifest passed.

- **Direction** (both kinds; :mod:`.azimuth`): up to 50 neighbour pairs along x and 50 along
  y (drawn with a seed) are homed under the manifest's direction and under its mirror image.
  With the right one the residuals (true home direction - estimate) are one constant, with
  the mirrored one pairs along x and along y disagree by 180 deg: mean AE once the best
  offset is removed 1.6-5.9 deg against 88.7-91.1 deg. A verdict needs the better below 30
  deg, 20 deg between the two and 20 pairs homed; otherwise the direction is "undetermined"
  (files that are not the positions their names say, an elevation range far off).
- **Azimuth zero** (``zero_column``, ``zero_angle_deg``; or ``heading_deg``): the constant,
  fitted per way (+x, -x, +y, -y) and averaged. Right manifests: within 0.63 deg of the
  truth (standard errors 0.1-0.7 deg); planted errors corrected to within 0.6 deg. It
  disagrees beyond 2 deg or 3 standard errors, whichever is larger.
- **Mirror centre** (raw; :mod:`.rim`): the circle fitted to the rim of the mean image;
  within 0.1 px on generated images. It disagrees beyond 2 px (at a Bielefeld image's
  horizon radius, 154 px, 2 px turn azimuths by at most 0.75 deg). Homing runs about the
  rim's centre.
- **Horizon** (raw: the radial profile's ``elevations_deg``; panoramas: their elevation
  range; :mod:`.horizon`): where vertical flow between neighbours changes sign, on panoramas
  of at least 3 rows per degree: within 0.8 deg (raw, 2.1 px) and 1.1 deg (panoramas) of the
  truth with right manifests. It disagrees beyond 2 deg. The correction shifts every
  elevation alike (the mirror's or lens's angular range kept).

The homing method is min-warping (Möller's defaults but its band): robust where warping
fails (neighbour pairs of synth-original: median AE 1.4 deg against warping's 4.7; in the
outdoor square warping gives no estimate at all, reading the 0.3 m steps as no
displacement) and fast enough (about 10 ms a pair). Its band is moved below the horizon, to
[-40, 5] deg, where the floor is near and moves most: with its default +-15 deg band its
residuals in the outdoor square depend on the way of the move (-15 deg along +x, 0 along -y:
the offset came out 6 deg off), with the lower band they are within 1.25 deg (a band
column) in every style.

Time: ``homebench data check synth-original`` (10 x 17, raw and unfolded images) takes 9.5 s
of CPU, 20-25 s of wall time on 2 cores that other work kept at a load of 7-10.
"""

from homebench.data.check.checker import METHOD, check_database
from homebench.data.check.findings import Finding, KindCheck
from homebench.data.check.posed import PosedCheck, check_posed
from homebench.data.check.text import posed_report_lines, report_lines

__all__ = [
    "METHOD",
    "Finding",
    "KindCheck",
    "PosedCheck",
    "check_database",
    "check_posed",
    "posed_report_lines",
    "report_lines",
]
