"""``sailor replay bag``: rosbag2 bags (MCAP and SQLite3) through the perceptual and anchoring
layers, with no ROS graph; and one clear error for every kind of bad bag."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.serialization import serialize_message
from rosbags.rosbag2 import StoragePlugin, Writer

from merlin2_sailor.cli.main import main
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import open_store
from merlin2_sailor.ros.bags import BagReader
from merlin2_sailor.ros.bags.message_definitions import jazzy_typestore

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bag_scenes import TOPICS, Scene, write_bag  # noqa: E402


def replay(bag: Path, output: Path, capsys, *options: str) -> dict:
    assert main(["replay", "bag", str(bag), "--output", str(output), "--no-video", *options]) == 0, capsys.readouterr()
    return json.loads((output / "anchors.json").read_text())


def confirmed(saved: dict) -> dict[str, tuple[str, list[float]]]:
    return {anchor["symbol"]: (anchor["class"], anchor["position_m"])
            for anchor in saved["anchors"] if anchor["state"] == "confirmed"}


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_bag_replays_to_one_anchor_per_object_with_its_recorded_detections(tmp_path, capsys, storage) -> None:
    bag = write_bag(tmp_path / "bag", Scene(frames=6), storage)
    saved = replay(bag, tmp_path / "replay", capsys)
    assert saved["detector"] == "recorded" and saved["summary"]["frames"] == 6
    anchors = confirmed(saved)
    assert sorted(name for name, _ in anchors.values()) == ["book", "cup", "cup"]
    # The block is 2 m ahead, the wall 3 m: the camera looks along the world's x axis from 1 m up.
    depths = sorted(round(position[0], 1) for _, position in anchors.values())
    assert depths[0] == pytest.approx(2.0, abs=0.15) and depths[-1] == pytest.approx(3.0, abs=0.15)
    assert "rosbag2 bag" in capsys.readouterr().out
    # What the anchoring node would have told the knowledge base, as a store of its own.
    with open_store(f"sqlite://{tmp_path / 'replay' / 'knowledge.db'}") as knowledge:
        assert set(anchors) <= {pddl_object.name for pddl_object in knowledge.objects.get_all()}


def test_replays_of_one_scene_give_the_same_anchors_whatever_order_the_detections_came_in(tmp_path, capsys) -> None:
    ordered = replay(write_bag(tmp_path / "ordered", Scene(frames=5)), tmp_path / "a", capsys)
    again = replay(tmp_path / "ordered", tmp_path / "b", capsys)
    shuffled = replay(write_bag(tmp_path / "shuffled", Scene(frames=5, shuffle=True)), tmp_path / "c", capsys)
    assert confirmed(ordered) == confirmed(again)  # deterministic
    assert set(confirmed(shuffled)) == set(confirmed(ordered))
    for symbol, (name, position) in confirmed(ordered).items():
        assert confirmed(shuffled)[symbol][0] == name
        assert confirmed(shuffled)[symbol][1] == pytest.approx(position, abs=0.02)


def test_millimetre_depth_and_bgr_images_replay_like_metres_and_rgb(tmp_path, capsys) -> None:
    metres = confirmed(replay(write_bag(tmp_path / "m", Scene(frames=4)), tmp_path / "a", capsys))
    millimetres = confirmed(replay(write_bag(tmp_path / "mm", Scene(frames=4, depth_encoding="16UC1",
                                                                     color_encoding="bgr8")), tmp_path / "b", capsys))
    assert set(millimetres) == set(metres)
    for symbol, (_, position) in metres.items():
        assert millimetres[symbol][1] == pytest.approx(position, abs=0.01)


def test_the_camera_pose_can_come_from_the_bags_tf(tmp_path, capsys) -> None:
    pytest.importorskip("tf2_ros", reason="TF in a bag is read with tf2_ros (SAILOR_UPSTREAM builds it here)")
    from_topic = confirmed(replay(write_bag(tmp_path / "topic", Scene(frames=4)), tmp_path / "a", capsys))
    from_tf = confirmed(replay(write_bag(tmp_path / "tf", Scene(frames=4, pose="tf")), tmp_path / "b", capsys,
                               "--pose-topic", ""))
    assert set(from_tf) == set(from_topic)
    for symbol, (_, position) in from_topic.items():
        assert from_tf[symbol][1] == pytest.approx(position, abs=0.01)


# --- Bad bags: one line each, never a traceback ---------------------------------------------------


def error_of(capsys, *arguments: str) -> str:
    assert main(["replay", "bag", *arguments]) == 2
    error = capsys.readouterr().err.strip()
    assert "Traceback" not in error and error.startswith("sailor replay: error:"), error
    return error


def test_a_missing_path_or_a_folder_that_is_no_bag_is_said_so(tmp_path, capsys) -> None:
    assert "no bag at" in error_of(capsys, str(tmp_path / "nowhere"))
    (tmp_path / "folder").mkdir()
    assert "not a rosbag2 bag" in error_of(capsys, str(tmp_path / "folder"))
    assert "name the bag" in error_of(capsys)


def test_a_bag_cut_short_by_a_killed_recorder_is_said_so(tmp_path, capsys) -> None:
    bag = write_bag(tmp_path / "bag", Scene(frames=6))
    (data,) = bag.glob("*.mcap")
    content = data.read_bytes()
    data.write_bytes(content[: len(content) // 2])
    assert "damaged or cut short" in error_of(capsys, str(bag), "--output", str(tmp_path / "out"))


def test_a_bag_without_a_needed_topic_names_the_option_and_the_topics_it_has(tmp_path, capsys) -> None:
    bag = write_bag(tmp_path / "bag", Scene(frames=2))
    error = error_of(capsys, str(bag), "--depth-topic", "/camera/aligned_depth/image_raw")
    assert "no topic /camera/aligned_depth/image_raw" in error and "--depth-topic" in error
    assert TOPICS["depth"] in error  # among the topics it does have


def test_a_pose_topic_of_the_wrong_type_is_said_so(tmp_path, capsys) -> None:
    bag = write_bag(tmp_path / "bag", Scene(frames=2))
    assert "a camera pose is one of" in error_of(capsys, str(bag), "--pose-topic", TOPICS["info"])


def test_a_type_that_is_not_installed_is_named(tmp_path, capsys) -> None:
    bag = tmp_path / "bag"
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic in (TOPICS["color"], TOPICS["depth"], TOPICS["info"]):
            connection = writer.add_connection(topic, "acme_msgs/msg/Blob", msgdef="uint8 value\n",
                                               rihs01="RIHS01_" + "0" * 64)
            writer.write(connection, 1, b"\x00\x01\x00\x00\x07")
        pose = writer.add_connection(TOPICS["pose"], "geometry_msgs/msg/PoseStamped", typestore=jazzy_typestore())
        writer.write(pose, 1, serialize_message(PoseStamped()))
    error = error_of(capsys, str(bag))
    assert "acme_msgs/msg/Blob" in error and "not installed" in error


def test_frames_of_an_unusable_encoding_are_skipped_with_one_line(tmp_path, capsys) -> None:
    saved = replay(write_bag(tmp_path / "bag", Scene(frames=3, color_encoding="mono8")), tmp_path / "out", capsys)
    assert saved["summary"]["frames"] == 0 and saved["source_settings"]["frames_skipped"] == {
        "frame that does not convert": 3}
    said = [line for line in capsys.readouterr().err.splitlines() if "skipped" in line]
    assert len(said) == 1 and "mono8" in said[0]


def test_the_reader_refuses_a_path_that_is_not_there(tmp_path) -> None:
    with pytest.raises(ConfigurationError, match="no bag"):
        BagReader(tmp_path / "absent")


def test_the_percept_generators_parameters_come_from_the_launch_file_as_the_node_gets_them(tmp_path) -> None:
    import argparse

    from merlin2_sailor.cli.bag_replay_options import percept_parameters
    from merlin2_sailor_demos.replay.bag_source import BagSource, BagSourceConfig

    launched = percept_parameters(argparse.Namespace(launch="house", params=[]))
    assert launched["maximum_depth"] == 4.5 and launched["world_frame"] == "map"  # inline, then the file's
    assert percept_parameters(argparse.Namespace(launch="", params=[]))["maximum_depth"] == 20.0
    source = BagSource(BagSourceConfig(data=str(write_bag(tmp_path / "bag", Scene(frames=2))),
                                       percept_parameters={**launched, "slop": 0.01}))
    assert source.percept_config().box3d.maximum_depth == 4.5 and source.slop == 0.01
