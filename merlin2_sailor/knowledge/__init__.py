"""The symbolic layer: the PDDL knowledge model, its stores, grounding and synchronisation.

ROS-free: nothing here imports rclpy or message types. The names below are the public API; the
ROS nodes convert messages to and from them in ``merlin2_sailor.ros.conversions``.
"""

from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind, Operation
from merlin2_sailor.knowledge.grounding import (
    GroundableAnchor,
    GroundedAnchor,
    Grounding,
    GroundingConfig,
    Region,
    SizeCategory,
    Waypoint,
)
from merlin2_sailor.knowledge.model import (
    ROOT_TYPE,
    Condition,
    Effect,
    KnowledgeItem,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    Timing,
)
from merlin2_sailor.knowledge.naming import is_identifier, symbol, to_identifier
from merlin2_sailor.knowledge.pddl_writer import (
    domain_from_store,
    domain_text,
    problem_from_store,
    problem_text,
)
from merlin2_sailor.knowledge.store import DataAccessObject, KnowledgeBase, Subscriber
from merlin2_sailor.knowledge.stores import open_store
from merlin2_sailor.knowledge.sync import KnowledgeSync, SyncPlan

__all__ = [
    "ROOT_TYPE",
    "Change",
    "ChangeEvent",
    "Condition",
    "DataAccessObject",
    "Effect",
    "GroundableAnchor",
    "GroundedAnchor",
    "Grounding",
    "GroundingConfig",
    "ItemKind",
    "KnowledgeBase",
    "KnowledgeItem",
    "KnowledgeSync",
    "Operation",
    "Parameter",
    "PddlAction",
    "PddlObject",
    "PddlType",
    "Predicate",
    "Proposition",
    "Provenance",
    "Region",
    "SizeCategory",
    "Subscriber",
    "SyncPlan",
    "Timing",
    "Waypoint",
    "domain_from_store",
    "domain_text",
    "is_identifier",
    "open_store",
    "problem_from_store",
    "problem_text",
    "symbol",
    "to_identifier",
]
