"""The ROS 2 layer: message conversions, parameters, QoS profiles and the nodes.

Nodes only convert messages to core objects and back, hold parameters and schedule work; every
algorithm they run lives in the ROS-free subpackages.
"""
