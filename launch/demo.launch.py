"""ros2 launch merlin2_sailor demo.launch.py: the same graph as launch/demo.yaml.

The house graph of house.launch.py, plus the mission_demo node that runs the missions and writes
the report under ${SAILOR_DATA}/report.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    share = get_package_share_directory("merlin2_sailor")
    data = os.environ.get("SAILOR_DATA", os.path.join(os.path.expanduser("~"), ".sailor", "house"))
    house = IncludeLaunchDescription(PythonLaunchDescriptionSource(os.path.join(share, "launch", "house.launch.py")))
    return LaunchDescription([
        house,
        Node(package="merlin2_sailor", executable="mission_demo",
             parameters=[{"report_folder": os.path.join(data, "report"), "data_folder": data}], output="screen"),
    ])
