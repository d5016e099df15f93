"""Measurements of a running graph (topic rates, message ages) without ROS command-line tools."""
