"""The knowledge_base node's interface: its topic, and the services and codecs of each kind of item.

The node serves these and :class:`~merlin2_sailor.ros.knowledge_base_client.RemoteKnowledgeBase`
calls them; both read them from here, so neither imports the other.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from merlin2_sailor.knowledge.changes import ItemKind
from merlin2_sailor.knowledge.model import KnowledgeItem
from merlin2_sailor.ros.conversions import knowledge as convert
from merlin2_sailor_interfaces import srv

CHANGES_TOPIC = "knowledge_changes"
"""Every batch that changed something, with its number and its writer (relative name)."""

APPLY_CHANGES_SERVICE = "apply_changes"
"""A batch of changes in one transaction (relative name)."""


@dataclass(frozen=True)
class KindServices:
    """The service types and message codecs of one kind of item."""

    kind: ItemKind
    plural: str
    get_type: Any
    update_type: Any
    delete_all_type: Any
    to_message: Callable[[Any], Any]
    from_message: Callable[[Any], KnowledgeItem]


KIND_SERVICES = (
    KindServices(ItemKind.TYPE, "types", srv.GetTypes, srv.UpdateType, srv.DeleteAllTypes,
                 convert.type_to_message, convert.type_from_message),
    KindServices(ItemKind.OBJECT, "objects", srv.GetObjects, srv.UpdateObject, srv.DeleteAllObjects,
                 convert.object_to_message, convert.object_from_message),
    KindServices(ItemKind.PREDICATE, "predicates", srv.GetPredicates, srv.UpdatePredicate,
                 srv.DeleteAllPredicates, convert.predicate_to_message, convert.predicate_from_message),
    KindServices(ItemKind.PROPOSITION, "propositions", srv.GetPropositions, srv.UpdateProposition,
                 srv.DeleteAllPropositions, convert.proposition_to_message,
                 convert.proposition_from_message),
    KindServices(ItemKind.ACTION, "actions", srv.GetActions, srv.UpdateAction, srv.DeleteAllActions,
                 convert.action_to_message, convert.action_from_message),
)
