"""What Brains on Board's headings and Ant World images mean, settled from BoB's code and
checked on BoB's own example images.

**Headings** (``Heading [degrees]`` of ``database_entries.csv``) are compass bearings:
clockwise from +y. BoB's Ant World writes them so: ``RouteContinuous::rebuildRoute``
(``src/antworld/route_continuous.cc``) stores each segment's ``atan2(start.y - end.y, end.x -
start.x)`` and ``getPose`` returns ``90_deg + heading``, which for a step at angle t (ccw from
+x) is 90 - t, the bearing of the step; ``tools/ant_world_db_creator`` records that pose's yaw.
On BoB's ``example_route`` the step (6300, 8450) -> (6293.58, 8442.34) mm is recorded as
219.962: its compass bearing ``atan2(dx, dy)`` is 219.97, its ccw angle 230.03; over the 812
rows of ``routes/ant1_route1`` of BoB's ``ant_world_image_databases`` the headings equal the
bearing of the step into each image to a median 0.04 deg (of the step out of it: 0.58 deg),
and differ from the ccw angle of travel by a median 73.7 deg.
``include/navigation/insilico_rotater.h`` reports a roll of an image by k columns to the right
as a heading of k 360 / W, again a bearing.
(BoB's ``AntAgent::updatePose`` moves an agent along (cos yaw, sin yaw), a ccw reading; the
databases follow the renderer and the route, not that.)

**Ant World images** (``camera.name: opengl``: ``ant_world_db_creator``'s renders). A W x H
image with recorded heading h has column c (0 = left, centre at c + 0.5) looking along the
bearing ``h + 360 (c + 0.5 - W/2) / W`` and row r (0 = top) at elevation ``60 - 75 (r + 0.5)
/ H`` degrees. So the heading lies between columns W/2 - 1 and W/2 (homebench's zero column
W/2 - 0.5), column 0 looks backwards, the bearing grows to the right (homebench's azimuths,
ccw, shrink: direction ``cw``), and the image spans +60 to -15 deg, the horizon at row 0.8 H.
Read from: ``src/antworld/render_mesh.cc`` (``RenderMeshSpherical``: the screen's x runs
over "latitude" -hFOV/2 .. +hFOV/2, its y over "longitude" from ``startLongitude`` down by
vFOV, the cube-map direction (sin lat cos lon, sin lon, cos lat cos lon)),
``src/antworld/renderer.cc`` (hFOV 360, vFOV 75, startLongitude 15 deg; the cube faces'
``gluLookAt`` with +z up; ``applyFrame``: ``glRotatef(yaw, 0, 0, 1)`` then ``glTranslatef(-x,
-y, -z)``), and ``src/video/opengl/opengl.cc`` (``glReadPixels`` then a vertical flip only).
With OpenGL's cube-map lookup, the direction (sin lat cos lon, sin lon, cos lat cos lon) is
the agent-frame direction (sin lat cos lon, cos lat cos lon, -sin lon): lat = 0 looks along
the agent's +y, which ``glRotatef(yaw)`` turns to world bearing yaw; lat grows to the
agent's +x, i.e. clockwise; elevation = -lon. Checked on BoB's real images
(``docs_source/example_image_databases``): a ray-cast of BoB's Ant World mesh
(``resources/antworld/world5000_gray.bin``, drawn with back faces culled as BoB's agent sets
OpenGL up) by this formula matches the three ``example_route`` images to a mean absolute
difference of 0.0063-0.0066 (0-1 scale) with the best extra turn 0.0 deg; the mirrored
formula fits 8-9 times worse (0.054-0.056) at any turn.

BoB's grid recorder labels grids in another order than it visits them
(:mod:`homebench.data.grid_order`, ``bob-recorder``): ``homebench data check`` says whether a
grid carries it.
"""

from __future__ import annotations

import math

from homebench.geometry import HeadingConvention, PanoramaGeometry

#: BoB's headings: compass bearings, 0 along +y, growing clockwise.
BOB_HEADINGS = HeadingConvention(zero_deg=90.0, direction="cw")
#: The camera name BoB's Ant World renderer gives (``metadata.camera.name``).
ANT_WORLD_CAMERA = "opengl"
#: The Ant World renderer's vertical field of view: top and bottom elevation, degrees.
ANT_WORLD_ELEVATIONS_DEG = (60.0, -15.0)


def ant_world_panorama(size: tuple[int, int]) -> PanoramaGeometry:
    """The camera model of BoB's Ant World renders of ``size`` [width, height] (see the
    module docstring): +60 to -15 deg, the heading at column W/2 - 0.5, azimuths (ccw)
    shrinking to the right."""
    width, height = size
    top, bottom = (math.radians(e) for e in ANT_WORLD_ELEVATIONS_DEG)
    return PanoramaGeometry(width, height, top, bottom, "cw", width / 2.0 - 0.5)
