"""Items to plain documents and back, for the stores that keep documents (SQLite, MongoDB).

One codec for every database means an item reads back identical whatever store wrote it, and
decoding goes through the model's constructors, so a hand-edited database cannot smuggle an
invalid name into memory.
"""

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.changes import ItemKind, kind_of
from merlin2_sailor.knowledge.model import (
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
    TimedLiteral,
)

Document = dict[str, Any]

COLLECTION_NAMES: Mapping[ItemKind, str] = MappingProxyType(
    {
        ItemKind.TYPE: "types",
        ItemKind.OBJECT: "objects",
        ItemKind.PREDICATE: "predicates",
        ItemKind.PROPOSITION: "propositions",
        ItemKind.ACTION: "actions",
    }
)
"""Where each kind is kept: SQLite tables and MongoDB collections share names, and KANT's."""


def key_text(item: KnowledgeItem) -> str:
    """A readable, unique primary key: the name, or e.g. ``goal robot_at(robot, wp1)``."""
    return str(item) if isinstance(item, Proposition) else item.name


def to_document(item: KnowledgeItem) -> Document:
    """The fields of an item as JSON- and BSON-friendly values, named as in KANT."""
    match item:
        case PddlType():
            return {"name": item.name, "supertype": item.supertype}
        case PddlObject():
            return {"name": item.name, "type": item.type}
        case Predicate():
            return {"name": item.name, "parameter_types": list(item.parameter_types)}
        case Proposition():
            return {
                "predicate": item.predicate,
                "objects": list(item.objects),
                "is_goal": item.is_goal,
                "provenance": item.provenance.value,
            }
        case PddlAction():
            return {
                "name": item.name,
                "durative": item.durative,
                "duration": item.duration,
                "parameters": [{"name": p.name, "type": p.type} for p in item.parameters],
                "conditions": [_literal_document(literal) for literal in item.conditions],
                "effects": [_literal_document(literal) for literal in item.effects],
            }
    kind_of(item)  # Raises the model's error for anything that is not an item.
    raise AssertionError("unreachable")


def from_document(kind: ItemKind, document: Mapping[str, Any]) -> KnowledgeItem:
    """Rebuild an item, validating it like any other; a malformed document is a KnowledgeError."""
    try:
        match kind:
            case ItemKind.TYPE:
                return PddlType(document["name"], document["supertype"])
            case ItemKind.OBJECT:
                return PddlObject(document["name"], document["type"])
            case ItemKind.PREDICATE:
                return Predicate(document["name"], tuple(document["parameter_types"]))
            case ItemKind.PROPOSITION:
                return Proposition(
                    document["predicate"],
                    tuple(document["objects"]),
                    is_goal=bool(document["is_goal"]),
                    provenance=Provenance(document["provenance"]),
                )
            case ItemKind.ACTION:
                return PddlAction(
                    document["name"],
                    parameters=tuple(Parameter(**p) for p in document["parameters"]),
                    conditions=tuple(_literal(Condition, c) for c in document["conditions"]),
                    effects=tuple(_literal(Effect, e) for e in document["effects"]),
                    durative=bool(document["durative"]),
                    duration=float(document["duration"]),
                )
    except (KeyError, TypeError, ValueError) as error:
        raise KnowledgeError(
            f"stored {kind.value} {dict(document)!r} is malformed ({error!r}); "
            "delete it from the database or restore a backup"
        ) from error
    raise AssertionError(f"unknown kind {kind!r}")


def _literal_document(literal: TimedLiteral) -> Document:
    return {
        "predicate": literal.predicate,
        "arguments": list(literal.arguments),
        "time": None if literal.time is None else literal.time.value,
        "is_negative": literal.is_negative,
    }


def _literal(literal_class: type[TimedLiteral], document: Mapping[str, Any]) -> Any:
    return literal_class(
        document["predicate"],
        tuple(document["arguments"]),
        document["time"],
        bool(document["is_negative"]),
    )
