"""The QoS profiles of the project's topics, named once.

Camera streams use the sensor-data profile (best effort, shallow queue): a late frame is worth
less than the next one, and a best-effort subscriber also accepts reliable publishers. State
topics that a late joiner must still receive (the anchors, the knowledge base's changes) are
latched: reliable and transient-local with depth 1.
"""

from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)

SENSOR_DATA = qos_profile_sensor_data

LATCHED = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)

EVENTS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)

# Subscribes to anything: best effort and volatile are compatible with every publisher profile.
ANY_PUBLISHER = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)
