"""SAILOR symbolic anchoring for ROS 2 Jazzy, as a skill of the MERLIN2 cognitive architecture.

The subpackages ``perception``, ``anchoring``, ``knowledge``, ``training`` and ``launcher`` are
ROS-free: they import neither rclpy nor message types. Only ``merlin2_sailor.ros`` talks to ROS.
"""

__version__ = "0.1.0"
