"""The ground truth export is plain data; the markers, textures and grounding file match the house."""

from __future__ import annotations

import json

import numpy as np
import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor_demos.world.markers import world_markers
from merlin2_sailor_demos.world.textures import TextureLibrary, TextureSpec
from merlin2_sailor_demos.world.world import World

from .worlds import HOUSE_GROUNDING_FILE


def test_the_export_is_json_with_objects_poses_and_events(house_description) -> None:
    world = World(house_description, seed=0)
    truth = json.loads(json.dumps(world.ground_truth()))
    assert truth["robot"]["true_pose"] == world.true_pose.as_dict()
    assert truth["robot"]["room"] == "kitchen" and truth["robot"]["holding"] is None
    red_mug = next(item for item in truth["objects"] if item["id"] == "red_mug")
    assert red_mug["class"] == "cup" and red_mug["room"] == "kitchen" and len(red_mug["position"]) == 3
    assert set(truth["waypoints"]) == {"kitchen", "living_room", "hall", "bedroom"}
    assert truth["events"] == [] and truth["pending_events"] == ["red_mug_moves_to_the_living_room"]


def test_the_grounding_file_matches_the_house(house_description) -> None:
    grounding = GroundingConfig.from_yaml(HOUSE_GROUNDING_FILE)
    house = house_description.house
    assert [(w.name, w.x, w.y, w.yaw) for w in grounding.waypoints] == [
        (w.name, w.pose.x, w.pose.y, w.pose.yaw) for w in house.waypoints]
    assert [(r.name, r.x_min, r.y_min, r.x_max, r.y_max) for r in grounding.regions] == [
        (f"{r.name}_area", r.x_min, r.y_min, r.x_max, r.y_max) for r in house.rooms]
    classes = {spec.class_name for spec in house_description.objects}
    assert classes <= set(grounding.class_types)


def test_markers_show_walls_furniture_objects_and_waypoints(house_description) -> None:
    world = World(house_description)
    items = world_markers(world)
    counts = {namespace: sum(item.namespace == namespace for item in items)
              for namespace in {item.namespace for item in items}}
    house = house_description.house
    assert counts == {"walls": len(house.walls), "furniture": len(house.furniture),
                      "objects": len(world.objects), "object_labels": len(world.objects),
                      "waypoints": len(house.waypoints), "waypoint_labels": len(house.waypoints)}


def test_a_missing_darknet_photo_falls_back_and_says_so(tmp_path) -> None:
    specs = {
        "dog": TextureSpec("darknet/dog", fallback="skimage/chelsea", crop=(140, 208, 313, 535)),
        "kite": TextureSpec("darknet/kite"),
    }
    library = TextureLibrary(specs, darknet_data=str(tmp_path))
    dog = library.get("dog").image
    assert dog.ndim == 3 and dog.dtype == np.uint8 and max(dog.shape[:2]) <= 256
    assert library.substitutions == {"dog": "skimage/chelsea"}
    with pytest.raises(DependencyError, match="SAILOR_DARKNET_DATA"):
        library.get("kite")
