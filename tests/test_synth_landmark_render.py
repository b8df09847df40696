"""Generated worlds rendered as their ground-truth landmarks (``render: landmarks``): every
object black on a white room, no light and no camera; a spec field that leaves photo worlds'
keys alone."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from homebench.config import load_config
from homebench.data.synth.spec import GridSpec, RawImageSpec, UnfoldedImageSpec, WorldSpec
from homebench.data.synth.world import build_world, render_position
from homebench.geometry import wrap_angle

SMALL = {
    "grid": GridSpec(shape=(3, 3), spacing=0.3),
    "raw": RawImageSpec(width=200, height=150, inner_radius=8, outer_radius=70),
    "unfolded": UnfoldedImageSpec(width=360),
}


def _spec(**fields: object) -> WorldSpec:
    return WorldSpec(**{"style": "arena", **SMALL, **fields})


def test_the_render_field_enters_the_key_only_when_set():
    photo, landmarks = WorldSpec(), WorldSpec(render="landmarks")
    assert "render" not in json.loads(photo.canonical_json())
    assert WorldSpec(render="photo").key() == photo.key()
    assert json.loads(landmarks.canonical_json())["render"] == "landmarks"
    assert landmarks.key() != photo.key()


@pytest.mark.parametrize("position", [(0, 0), (2, 1)])
def test_the_cylinders_are_black_and_the_room_white(position):
    """Two grey levels only. A column whose azimuth span lies within a cylinder's angular
    extent (from the scene's geometry: bearing +- asin(radius / distance)) is 0 on the horizon
    row; one that lies outside every cylinder's is 255 from top to bottom (floor, walls and
    ceiling alike)."""
    spec = _spec(render="landmarks")
    world, pose = build_world(spec), spec.pose(*position)
    geometry = spec.unfolded.geometry()
    image = render_position(spec, *position)["unfolded"]
    row = image[int(round(geometry.horizon_row))].astype(float)
    azimuth = geometry.column_to_azimuth(np.arange(geometry.width))
    half_column = geometry.column_step / 2
    inside, outside = np.zeros(geometry.width, bool), np.ones(geometry.width, bool)
    for cylinder in world.scene.objects:
        offset = np.array(cylinder.centre) - pose.xy
        bearing = math.atan2(offset[1], offset[0]) - pose.heading
        half = math.asin(cylinder.radius / math.hypot(*offset))
        gap = np.abs(wrap_angle(azimuth - bearing))
        inside |= gap < half - half_column
        outside &= gap > half + half_column
    assert inside.sum() >= 8 and outside.sum() > 300
    assert np.all(row[inside] == 0) and np.all(image[:, outside] == 255)
    assert set(np.unique(image)) == {0, 255}


def test_no_light_and_no_camera():
    """The images do not depend on the noise seed or the light, only on the objects: the day
    variant's are the original's, the arboreal variant's plant adds dark pixels; the raw
    image is black outside the mirror's annulus."""
    original = build_world(_spec(render="landmarks"))
    pose = original.spec.pose(1, 1)
    images = original.render(pose, 1)
    again = original.render(pose, 2)
    day = build_world(_spec(render="landmarks", variant="day")).render(pose, 3)
    plant = build_world(_spec(render="landmarks", variant="arboreal")).render(pose, 1)
    for kind in ("raw", "unfolded"):
        assert np.array_equal(images[kind], again[kind])
        assert np.array_equal(images[kind], day[kind])
    assert np.count_nonzero(plant["unfolded"] < images["unfolded"]) > 100
    assert np.all(images["raw"][~original.raw_geometry.annulus_mask()] == 0)


def test_a_config_runs_a_world_beside_its_ground_truth_landmarks(tmp_path: Path):
    data = {
        "name": "control",
        "output": str(tmp_path / "run"),
        "databases": {
            "photo": {"world": {"style": "posters"}},
            "truth": {"world": {"style": "posters", "render": "landmarks"}},
        },
        "conditions": ["photo-photo", "truth-truth"],
        "goals": [[1, 1]],
        "methods": [{"method": "alv"}, {"method": "snapshot"}],
    }
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(data))
    config = load_config(path)
    photo, truth = (config.databases[name].world for name in ("photo", "truth"))
    assert photo is not None and truth is not None
    assert (photo.render, truth.render) == ("photo", "landmarks")
    assert truth.key() != photo.key() == WorldSpec(style="posters").key()
