"""The PDDL knowledge model to merlin2_sailor_interfaces messages and back.

Messages are shaped like KANT's, so these functions are also the bridge to MERLIN2. Reading a
message builds a model item, whose constructor validates names, arities and timings: a malformed
request from the network surfaces as KnowledgeError with the reason, which the node returns in
the service response instead of storing nonsense.
"""

from __future__ import annotations

from types import MappingProxyType

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import model
from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind, Operation, kind_of
from merlin2_sailor_interfaces.msg import (
    KnowledgeChange,
    PddlAction,
    PddlLiteral,
    PddlObject,
    PddlParameter,
    PddlPredicate,
    PddlProposition,
    PddlType,
)

_PROVENANCE_TO_MESSAGE = MappingProxyType({
    model.Provenance.PERCEIVED: PddlProposition.PROVENANCE_PERCEIVED,
    model.Provenance.EXPECTED: PddlProposition.PROVENANCE_EXPECTED,
    model.Provenance.DECLARED: PddlProposition.PROVENANCE_DECLARED,
})
_PROVENANCE_FROM_MESSAGE = MappingProxyType({value: key for key, value in _PROVENANCE_TO_MESSAGE.items()})


def type_to_message(item: model.PddlType) -> PddlType:
    supertype = "" if item.supertype == model.ROOT_TYPE else item.supertype
    return PddlType(name=item.name, supertype=supertype)


def type_from_message(message: PddlType) -> model.PddlType:
    return model.PddlType(message.name, message.supertype or model.ROOT_TYPE)


def object_to_message(item: model.PddlObject) -> PddlObject:
    return PddlObject(name=item.name, type=item.type)


def object_from_message(message: PddlObject) -> model.PddlObject:
    return model.PddlObject(message.name, message.type)


def predicate_to_message(item: model.Predicate) -> PddlPredicate:
    return PddlPredicate(name=item.name, parameter_types=list(item.parameter_types))


def predicate_from_message(message: PddlPredicate) -> model.Predicate:
    return model.Predicate(message.name, tuple(message.parameter_types))


def proposition_to_message(item: model.Proposition) -> PddlProposition:
    return PddlProposition(
        predicate=item.predicate, objects=list(item.objects), is_goal=item.is_goal,
        provenance=_PROVENANCE_TO_MESSAGE[item.provenance],
    )


def proposition_from_message(message: PddlProposition) -> model.Proposition:
    try:
        provenance = _PROVENANCE_FROM_MESSAGE[message.provenance]
    except KeyError:
        raise KnowledgeError(
            f"unknown provenance {message.provenance} on proposition {message.predicate!r}; "
            "use one of PddlProposition.PROVENANCE_*"
        ) from None
    return model.Proposition(message.predicate, tuple(message.objects), message.is_goal, provenance)


def _literal_to_message(literal: model.TimedLiteral) -> PddlLiteral:
    return PddlLiteral(
        predicate=literal.predicate, arguments=list(literal.arguments),
        time=literal.time.value if literal.time is not None else "", is_negative=literal.is_negative,
    )


def action_to_message(item: model.PddlAction) -> PddlAction:
    return PddlAction(
        name=item.name, durative=item.durative, duration=float(item.duration),
        parameters=[PddlParameter(name=p.name, type=p.type) for p in item.parameters],
        conditions=[_literal_to_message(condition) for condition in item.conditions],
        effects=[_literal_to_message(effect) for effect in item.effects],
    )


def action_from_message(message: PddlAction) -> model.PddlAction:
    def literal(literal_message: PddlLiteral, literal_class: type[model.TimedLiteral]) -> model.TimedLiteral:
        return literal_class(
            literal_message.predicate, tuple(literal_message.arguments),
            literal_message.time or None, literal_message.is_negative,
        )

    return model.PddlAction(
        name=message.name,
        parameters=tuple(model.Parameter(p.name, p.type or model.ROOT_TYPE) for p in message.parameters),
        conditions=tuple(literal(c, model.Condition) for c in message.conditions),
        effects=tuple(literal(e, model.Effect) for e in message.effects),
        durative=message.durative,
        duration=message.duration if message.durative else model.DEFAULT_ACTION_DURATION,
    )


# kind -> (field of KnowledgeChange, to message, from message)
_CODECS = MappingProxyType({
    ItemKind.TYPE: ("pddl_type", type_to_message, type_from_message),
    ItemKind.OBJECT: ("pddl_object", object_to_message, object_from_message),
    ItemKind.PREDICATE: ("pddl_predicate", predicate_to_message, predicate_from_message),
    ItemKind.PROPOSITION: ("pddl_proposition", proposition_to_message, proposition_from_message),
    ItemKind.ACTION: ("pddl_action", action_to_message, action_from_message),
})


def item_to_message(item: model.KnowledgeItem) -> object:
    """Any model item to its message."""
    return _CODECS[kind_of(item)][1](item)


def item_from_change_message(message: KnowledgeChange) -> tuple[ItemKind, model.KnowledgeItem]:
    kind = _kind_from_text(message.kind)
    field_name, _, from_message = _CODECS[kind]
    return kind, from_message(getattr(message, field_name))


def event_to_message(event: ChangeEvent) -> KnowledgeChange:
    field_name, to_message, _ = _CODECS[event.kind]
    message = KnowledgeChange(operation=event.operation.value, kind=event.kind.value)
    setattr(message, field_name, to_message(event.item))
    return message


def event_from_message(message: KnowledgeChange) -> ChangeEvent:
    kind, item = item_from_change_message(message)
    return ChangeEvent(_operation_from_value(message.operation), kind, item)


def change_to_message(change: Change) -> KnowledgeChange:
    """A requested change to its message; a delete by key alone carries just the key's fields."""
    message = KnowledgeChange(operation=change.operation.value, kind=change.kind.value)
    field_name, to_message, _ = _CODECS[change.kind]
    if change.item is not None:
        setattr(message, field_name, to_message(change.item))
    elif change.kind is ItemKind.PROPOSITION:
        predicate, objects, is_goal = change.key  # type: ignore[misc]
        message.pddl_proposition = PddlProposition(predicate=predicate, objects=list(objects), is_goal=is_goal)
    else:
        getattr(message, field_name).name = str(change.key)
    return message


def change_from_message(message: KnowledgeChange) -> Change:
    """Read a requested change; a delete needs only the item's identity, not its other fields."""
    operation = _operation_from_value(message.operation)
    kind = _kind_from_text(message.kind)
    field_name = _CODECS[kind][0]
    if operation is Operation.SAVE:
        return Change.save(item_from_change_message(message)[1])
    if kind is ItemKind.PROPOSITION:
        proposition = message.pddl_proposition
        return Change.delete_key(kind, (proposition.predicate, tuple(proposition.objects), proposition.is_goal))
    return Change.delete_key(kind, getattr(message, field_name).name)


def _kind_from_text(text: str) -> ItemKind:
    try:
        return ItemKind(text)
    except ValueError:
        kinds = ", ".join(kind.value for kind in ItemKind)
        raise KnowledgeError(f"unknown knowledge item kind {text!r}; use one of {kinds}") from None


def _operation_from_value(value: int) -> Operation:
    try:
        return Operation(value)
    except ValueError:
        raise KnowledgeError(f"unknown operation {value}; use OPERATION_SAVE (0) or OPERATION_DELETE (1)") from None
