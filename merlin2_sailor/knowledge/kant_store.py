"""KantStore: MERLIN2's own knowledge base (KANT) as one more KnowledgeBase store.

Where the real KANT Python packages are importable, SAILOR's anchors can be synchronised straight
into MERLIN2's knowledge base: this adapter turns our model items into KANT's DTOs and drives
KANT's data access objects (one per kind, each with get / get_all / save / delete / delete_all).

KANT is shared with the rest of MERLIN2 (missions and actions write to it too), so unlike the
local stores this one does not trust a mirror: it reloads KANT's content before every read and
every batch, checks the batch with the same rules as every other store, and writes the net
changes through the DAOs in dependency order. What KANT cannot hold is said plainly:

* no transactions: a batch that fails half-way leaves the changes written so far (in dependency
  order, so the knowledge base stays consistent);
* no subtypes, whole-second durations, no provenance: :mod:`.kant_projection` decides what KANT
  is given instead, and what this adapter remembers of what it wrote.

By location, ``kant+mongodb://host:port/database`` opens KANT's MongoDB DAO family on that URI;
``kant+ros:///namespace`` (:mod:`merlin2_sailor.ros.kant_ros_store`) its ROS 2 family, KANT's own
node, from ROS nodes and ``sailor`` commands.
"""

from __future__ import annotations

import importlib
from collections.abc import Hashable, Iterable, Sequence
from types import ModuleType
from typing import Any

from merlin2_sailor.errors import ConfigurationError, DependencyError, KnowledgeError
from merlin2_sailor.knowledge import model
from merlin2_sailor.knowledge.changes import ChangeEvent, ItemKind, Operation
from merlin2_sailor.knowledge.kant_projection import KantKinds, KantProjection, item_key, kant_duration
from merlin2_sailor.knowledge.mirrored_store import MirroredStore
from merlin2_sailor.knowledge.model import KnowledgeItem, Proposition
from merlin2_sailor.knowledge.rules import KnowledgeState
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS

#: ``kant+mongodb://host:port/database``: KANT's MongoDB family; what follows ``kant+`` is KANT's URI.
MONGODB_SCHEME = "kant+mongodb://"
_KINDS_IN_ORDER = (ItemKind.TYPE, ItemKind.PREDICATE, ItemKind.OBJECT, ItemKind.PROPOSITION, ItemKind.ACTION)
"""Dependencies first: what KANT must hold before a fact or an action can refer to it."""
KANT_MISSING = (
    "the KANT store needs MERLIN2's kant_dto and kant_dao packages; build KANT in your "
    "ROS 2 workspace (https://github.com/uleroboticsgroup/kant) and source it"
)


def import_kant_dto() -> ModuleType:
    return import_kant_module("kant_dto")


def import_kant_module(module_name: str) -> ModuleType:
    """A module of KANT (or of what it needs), or a DependencyError saying how to get KANT."""
    try:
        return importlib.import_module(module_name)
    except ImportError as error:
        raise DependencyError(f"{KANT_MISSING} ({error})") from error


class KantStore(MirroredStore):
    """A KnowledgeBase over KANT's DAOs, made by one of KANT's DAO factories.

    ``dao_factory`` is what KANT's ``DaoFactoryMethod().create_dao_factory(family, ...)`` returns
    (ROS 2 services of MERLIN2's KB node, or MongoDB); ``dto_module`` defaults to ``kant_dto``.
    """

    def __init__(self, dao_factory: Any, dto_module: ModuleType | None = None) -> None:
        super().__init__()
        self._dto = dto_module if dto_module is not None else import_kant_dto()
        self._daos = {
            ItemKind.TYPE: dao_factory.create_pddl_type_dao(),
            ItemKind.OBJECT: dao_factory.create_pddl_object_dao(),
            ItemKind.PREDICATE: dao_factory.create_pddl_predicate_dao(),
            ItemKind.PROPOSITION: dao_factory.create_pddl_proposition_dao(),
            ItemKind.ACTION: dao_factory.create_pddl_action_dao(),
        }
        self._projection = KantProjection()
        # Items of the batch being written, for DTOs of things the same batch deleted.
        self._batch_items: dict[tuple[ItemKind, Hashable], KnowledgeItem] = {}
        self._open_mirror()

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> KantStore:
        """``kant+mongodb://host:port/database``: KANT's DAOs over its MongoDB family."""
        uri = location.removeprefix("kant+")
        if location == MONGODB_SCHEME or not location.startswith(MONGODB_SCHEME):
            raise ConfigurationError(
                f"{location!r} names no KANT database; write kant+mongodb://host:port/database"
            )
        dao_factory_module = import_kant_module("kant_dao.dao_factory")
        families = dao_factory_module.DaoFamilies
        return cls(dao_factory_module.DaoFactoryMethod().create_dao_factory(families.MONGO, uri=uri))

    # The port, reading KANT afresh each time.

    def get(self, kind: ItemKind, key: Hashable) -> KnowledgeItem | None:
        with self._lock:
            self._reload()
            return super().get(kind, key)

    def get_all(self, kind: ItemKind) -> tuple[KnowledgeItem, ...]:
        with self._lock:
            self._reload()
            return super().get_all(kind)

    def propositions_about(self, object_name: str) -> tuple[Proposition, ...]:
        with self._lock:
            self._reload()
            return super().propositions_about(object_name)

    def apply(self, changes: Iterable[Any]) -> tuple[ChangeEvent, ...]:
        with self._lock:
            self._reload()
            return super().apply(changes)

    # What MirroredStore needs.

    def _reload(self) -> None:
        self._require_open()
        self._state = KnowledgeState()
        self._state.load(self._load())

    def _load(self) -> list[KnowledgeItem]:
        items: list[KnowledgeItem] = []
        for kind in _KINDS_IN_ORDER:
            for dto in self._daos[kind].get_all() or []:
                if kind is ItemKind.TYPE and dto.get_name() == model.ROOT_TYPE:
                    continue  # MERLIN2's plain type 'object' is SAILOR's root, never declared
                items.append(self._projection.restore(kind, self._from_dto(kind, dto)))
        return items

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        before = self._projection.kinds
        self._projection.update(item for kind in _KINDS_IN_ORDER for item in self._state.get_all(kind))
        self._batch_items = {(event.kind, getattr(event.item, "name", None)): event.item for event in events}
        deletions = [event for event in events if event.operation is Operation.DELETE]
        saves = [event for event in events if event.operation is Operation.SAVE]
        saves += self._retyped(before, {item_key(event.kind, event.item) for event in events})
        saves.sort(key=lambda event: _KINDS_IN_ORDER.index(event.kind))
        for event in (*deletions, *saves):
            self._write(event)

    def _retyped(self, before: KantKinds, batch_keys: set) -> list[ChangeEvent]:
        """Saves of items this batch left alone whose KANT types it changed (two kinds met)."""
        changed = set(before.mapping.items()) ^ set(self._projection.kinds.mapping.items())
        if not changed:
            return []
        retyped = []
        for kind in (ItemKind.PREDICATE, ItemKind.OBJECT, ItemKind.ACTION):
            for item in self._state.get_all(kind):
                if item_key(kind, item) not in batch_keys and self._projected_differently(item, before):
                    retyped.append(ChangeEvent(Operation.SAVE, kind, item))
        return retyped

    def _projected_differently(self, item: KnowledgeItem, before: KantKinds) -> bool:
        now = self._projection.kinds
        if isinstance(item, model.PddlObject):
            return before(item.type) != now(item.type)
        if isinstance(item, model.Predicate):
            return any(before(t) != now(t) for t in item.parameter_types)
        return any(before(p.type) != now(p.type) for p in item.parameters)  # type: ignore[union-attr]

    def _write(self, event: ChangeEvent) -> None:
        projected = self._projection.project(event.item)
        if projected is None:
            return
        dao = self._daos[event.kind]
        dto = self._to_dto(projected)
        if event.operation is Operation.SAVE:
            if dao.save(dto) is False:
                raise KnowledgeError(f"KANT refused to save {event.kind.value} {projected}")
            self._projection.remember(event.kind, event.item)
        else:
            if dao.delete(dto) is False and self._still_in_kant(event.kind, projected):
                raise KnowledgeError(f"KANT refused to delete {event.kind.value} {projected}")
            self._projection.forget(event.kind, event.item)

    def _still_in_kant(self, kind: ItemKind, item: KnowledgeItem) -> bool:
        """Whether KANT still holds an item it would not delete (KANT cascades some deletions)."""
        if kind is ItemKind.PROPOSITION:
            return any(self._from_dto(kind, dto) == item for dto in self._daos[kind].get_all() or [])
        return self._daos[kind].get(item.name) is not None  # type: ignore[union-attr]

    def _close_database(self) -> None:
        """KANT's DAOs hold no resources of ours."""

    # Model items <-> KANT DTOs.

    def _type_dto(self, name: str) -> Any:
        return self._dto.PddlTypeDto(name)

    def _stored(self, kind: ItemKind, name: str) -> Any:
        """The item as KANT holds it, from this batch's state."""
        item = self._state.get(kind, name) or self._batch_items.get((kind, name))
        return None if item is None else self._projection.project(item)

    def _object_dto(self, name: str) -> Any:
        stored = self._stored(ItemKind.OBJECT, name)
        if stored is None:
            raise KnowledgeError(f"object {name!r} is not in the knowledge base")
        return self._dto.PddlObjectDto(self._type_dto(stored.type), name)

    def _predicate_dto(self, name: str) -> Any:
        stored = self._stored(ItemKind.PREDICATE, name)
        if stored is None:
            raise KnowledgeError(f"predicate {name!r} is not in the knowledge base")
        return self._dto.PddlPredicateDto(name, [self._type_dto(t) for t in stored.parameter_types])

    def _to_dto(self, item: KnowledgeItem) -> Any:
        if isinstance(item, model.PddlType):
            return self._type_dto(item.name)
        if isinstance(item, model.PddlObject):
            return self._dto.PddlObjectDto(self._type_dto(item.type), item.name)
        if isinstance(item, model.Predicate):
            return self._dto.PddlPredicateDto(item.name, [self._type_dto(t) for t in item.parameter_types])
        if isinstance(item, model.Proposition):
            return self._dto.PddlPropositionDto(
                self._predicate_dto(item.predicate), [self._object_dto(o) for o in item.objects], item.is_goal
            )
        return self._action_dto(item)  # type: ignore[arg-type]

    def _action_dto(self, action: model.PddlAction) -> Any:
        parameters = {p.name: self._dto.PddlObjectDto(self._type_dto(p.type), p.name) for p in action.parameters}

        def literal(item: model.TimedLiteral) -> Any:
            return self._dto.PddlConditionEffectDto(
                self._predicate_dto(item.predicate), [parameters[name] for name in item.arguments],
                item.time.value if item.time is not None else None, item.is_negative,
            )

        dto = self._dto.PddlActionDto(
            action.name, list(parameters.values()), [literal(c) for c in action.conditions],
            [literal(e) for e in action.effects], action.durative,
        )
        dto.set_duration(kant_duration(action.duration))
        return dto

    def _from_dto(self, kind: ItemKind, dto: Any) -> KnowledgeItem:
        if kind is ItemKind.TYPE:
            return model.PddlType(dto.get_name())
        if kind is ItemKind.OBJECT:
            return model.PddlObject(dto.get_name(), dto.get_type().get_name())
        if kind is ItemKind.PREDICATE:
            return model.Predicate(dto.get_name(), tuple(t.get_name() for t in dto.get_types()))
        if kind is ItemKind.PROPOSITION:
            return model.Proposition(
                dto.get_predicate().get_name(), tuple(o.get_name() for o in dto.get_objects()),
                dto.get_is_goal(),
            )

        def literal(item: Any, literal_class: type[model.TimedLiteral]) -> model.TimedLiteral:
            return literal_class(item.get_predicate().get_name(), tuple(o.get_name() for o in item.get_objects()),
                                 item.get_time() or None, item.get_is_negative())

        return model.PddlAction(
            name=dto.get_name(),
            parameters=tuple(model.Parameter(p.get_name(), p.get_type().get_name()) for p in dto.get_parameters()),
            conditions=tuple(literal(c, model.Condition) for c in dto.get_conditions()),
            effects=tuple(literal(e, model.Effect) for e in dto.get_effects()),
            durative=dto.get_durative(),
            duration=float(dto.get_duration()) if dto.get_durative() else model.DEFAULT_ACTION_DURATION,
        )
