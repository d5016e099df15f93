"""rosbag2 bags (MCAP and SQLite3) without a ROS installation.

The ``rosbags`` library reads and writes the bag containers; the messages inside are CDR, the
same bytes DDS carries, and rclpy (de)serialises them into the message classes the nodes use,
so a bag's frames go through the nodes' own conversions. See :mod:`.bag_reader`,
:mod:`.bag_writer` and :mod:`.message_definitions`.
"""

from merlin2_sailor.ros.bags.bag_reader import BagMessage, BagReader
from merlin2_sailor.ros.bags.bag_writer import BAG_STORAGES, BagWriter

__all__ = ["BAG_STORAGES", "BagMessage", "BagReader", "BagWriter"]
