"""config/sailor.rviz: an RViz2 view of the anchors, percepts, simulated world and camera image."""

from __future__ import annotations

import yaml

from merlin2_sailor.resources import config_file


def load_rviz() -> dict:
    return yaml.safe_load(config_file("sailor.rviz").read_text())


def test_the_rviz_view_shows_every_sailor_topic_in_the_map_frame() -> None:
    manager = load_rviz()["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "map"
    displays = {display["Name"]: display for display in manager["Displays"]}
    assert set(displays) == {"Grid", "Anchors", "Percepts", "World", "Camera"}
    assert displays["Grid"]["Class"] == "rviz_default_plugins/Grid"
    assert displays["Grid"]["Reference Frame"] == "<Fixed Frame>"
    topics = {name: (display["Class"], display["Topic"]["Value"]) for name, display in displays.items()
              if "Topic" in display}
    assert topics == {
        "Anchors": ("rviz_default_plugins/MarkerArray", "/anchor_markers"),
        "Percepts": ("rviz_default_plugins/MarkerArray", "/camera/percept_markers"),
        "World": ("rviz_default_plugins/MarkerArray", "/world_markers"),
        "Camera": ("rviz_default_plugins/Image", "/camera/color/image_raw"),
    }
    assert all(display["Enabled"] for display in displays.values())


def test_each_display_subscribes_with_a_qos_its_publisher_can_serve() -> None:
    displays = {display["Name"]: display for display in load_rviz()["Visualization Manager"]["Displays"]}
    # The anchoring node latches its markers (reliable, transient local): a late RViz gets them.
    anchors = displays["Anchors"]["Topic"]
    assert (anchors["Reliability Policy"], anchors["Durability Policy"]) == ("Reliable", "Transient Local")
    # Camera streams are best effort; a reliable subscriber would never match them.
    for name in ("Percepts", "World", "Camera"):
        topic = displays[name]["Topic"]
        assert (topic["Reliability Policy"], topic["Durability Policy"]) == ("Best Effort", "Volatile"), name
