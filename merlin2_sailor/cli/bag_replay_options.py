"""The options of ``sailor replay bag PATH``: which topics of the bag are what, and the percept
generator's parameters, taken from the same files (or launch file) the node is started with."""

from __future__ import annotations

import argparse
from typing import Any

from merlin2_sailor.errors import ConfigurationError

#: The executable of the percept generator node in launch files.
PERCEPT_EXECUTABLE = "percept_generator"


def add_bag_arguments(parser: argparse.ArgumentParser) -> None:
    from merlin2_sailor_demos.replay.bag_source import BagSourceConfig

    defaults = BagSourceConfig()
    group = parser.add_argument_group(
        "bag topics", "which topics of the bag hold what (default: the simulated house's, as sailor demo --record "
                      "records them)")
    group.add_argument("--color-topic", default=defaults.color_topic, metavar="TOPIC",
                       help=f"colour images (default {defaults.color_topic})")
    group.add_argument("--depth-topic", default=defaults.depth_topic, metavar="TOPIC",
                       help=f"depth images registered to colour, 32FC1 m or 16UC1 mm (default {defaults.depth_topic})")
    group.add_argument("--camera-info-topic", default=defaults.camera_info_topic, metavar="TOPIC",
                       help=f"the colour camera's CameraInfo (default {defaults.camera_info_topic})")
    group.add_argument("--pose-topic", default=defaults.pose_topic, metavar="TOPIC",
                       help="the camera pose: PoseStamped of the optical frame, or Odometry of the base with the "
                            "percept generator's camera_extrinsics; '' takes it from /tf and /tf_static "
                            f"(default {defaults.pose_topic})")
    group.add_argument("--camera-frame", default="", metavar="FRAME",
                       help="TF only: the camera's optical frame (default: the images' frame_id)")
    group.add_argument("--detections-topic", default=defaults.detections_topic, metavar="TOPIC",
                       help="recorded detections (the project's DetectionArray, yolo_msgs/DetectionArray or "
                            "vision_msgs/Detection2DArray); '' or a topic the bag lacks runs --detector instead "
                            f"(default {defaults.detections_topic})")


def bag_options(arguments: argparse.Namespace) -> dict[str, Any]:
    """The BagSourceConfig fields the command line gives."""
    if not arguments.path:
        raise ConfigurationError("name the bag to replay: sailor replay bag PATH")
    return {
        "data": arguments.path, "color_topic": arguments.color_topic, "depth_topic": arguments.depth_topic,
        "camera_info_topic": arguments.camera_info_topic, "pose_topic": arguments.pose_topic,
        "camera_frame": arguments.camera_frame, "detections_topic": arguments.detections_topic,
        "percept_parameters": percept_parameters(arguments),
    }


def percept_parameters(arguments: argparse.Namespace) -> dict[str, Any]:
    """The percept generator node's parameters: from --launch's percept_generator node (its files
    and inline values, in order) or config/percept_generator.yaml, then the --params files."""
    from merlin2_sailor.anchoring.settings import read_parameter_file
    from merlin2_sailor.cli.anchoring_settings import launch_node_parameters
    from merlin2_sailor.resources import config_file, config_path

    if arguments.launch:
        sources, node = launch_node_parameters(arguments.launch, PERCEPT_EXECUTABLE, "percept generator")
    else:
        sources, node = [config_file("percept_generator.yaml")], f"/{PERCEPT_EXECUTABLE}"
    sources += [config_path(name, "percept_generator.yaml") for name in arguments.params]
    values: dict[str, Any] = {}
    for source in sources:
        values.update(source if isinstance(source, dict) else read_parameter_file(source, node=node))
    return values
