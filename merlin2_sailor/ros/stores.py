"""Knowledge stores as the ROS layer knows them: the ROS-free ones plus ``ros://``, the knowledge_base node.

The core's table (:data:`merlin2_sailor.knowledge.stores.STORES`) cannot name a ROS module, so
this layer extends it with the client of the knowledge_base node. Nodes and ``sailor`` commands
open every location they are configured with here: ``ros:///merlin2`` reaches the node,
``sqlite://...`` and the others open a local store as the core would.
"""

from __future__ import annotations

from merlin2_sailor.knowledge import stores
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS, KnowledgeBase

ROS = "ros"

#: The core's stores and the knowledge_base node's client.
STORES = stores.STORES.extended(
    {ROS: "merlin2_sailor.ros.knowledge_base_client:RemoteKnowledgeBase"},
    hints={ROS: "The ros:// store needs ROS 2 Jazzy (rclpy) and merlin2_sailor_interfaces: run "
                "scripts/setup.sh, or source your ROS 2 workspace."},
)


def open_store(location: str = stores.MEMORY, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> KnowledgeBase:
    """Open any store :func:`merlin2_sailor.knowledge.stores.open_store` opens, or ``ros:///namespace``.

    ``timeout`` is how long a ``ros://`` client waits for each service (and a MongoDB store for
    its server).
    """
    return stores.open_store(location, timeout=timeout, stores=STORES)
