"""Knowledge stores as the ROS layer knows them: the ROS-free ones plus the two served by ROS nodes.

``ros:///namespace`` is SAILOR's knowledge_base node; ``kant+ros:///namespace`` is KANT's, MERLIN2's
knowledge base, through KANT's own ROS 2 DAOs.

The core's table (:data:`merlin2_sailor.knowledge.stores.STORES`) cannot name a ROS module, so
this layer extends it with the client of the knowledge_base node. Nodes and ``sailor`` commands
open every location they are configured with here: ``ros:///merlin2`` reaches the node,
``sqlite://...`` and the others open a local store as the core would.
"""

from __future__ import annotations

from merlin2_sailor.knowledge import stores
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS, KnowledgeBase

ROS = "ros"
KANT_ROS = "kant+ros"

#: The core's stores and the knowledge_base node's client.
STORES = stores.STORES.extended(
    {
        ROS: "merlin2_sailor.ros.knowledge_base_client:RemoteKnowledgeBase",
        KANT_ROS: "merlin2_sailor.ros.kant_ros_store:KantRosStore",
    },
    hints={
        ROS: "The ros:// store needs ROS 2 Jazzy (rclpy) and merlin2_sailor_interfaces: run "
             "scripts/setup.sh, or source your ROS 2 workspace.",
        KANT_ROS: "The kant+ros:// store needs KANT (kant_dao, kant_msgs) and simple_node: source the "
                  "MERLIN2 workspace, or SAILOR_UPSTREAM with scripts/upstream_env.sh.",
    },
)


def open_store(location: str = stores.MEMORY, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> KnowledgeBase:
    """Open any store :func:`merlin2_sailor.knowledge.stores.open_store` opens, or ``ros:///namespace``.

    ``timeout`` is how long a ``ros://`` client waits for each service (and a MongoDB store for
    its server).
    """
    return stores.open_store(location, timeout=timeout, stores=STORES)
