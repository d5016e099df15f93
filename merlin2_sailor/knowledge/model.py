"""The knowledge model, shaped like KANT's so items convert one-to-one to MERLIN2's messages.

Items are frozen dataclasses: they are shared between the store, its subscribers and the sync
without copies, and a frozen item can be compared and hashed, which is what makes saving twice
idempotent. Names are validated, not repaired, on construction (see
:func:`~merlin2_sailor.knowledge.naming.require_identifier` for why); turn free text into a name
with :func:`~merlin2_sailor.knowledge.naming.to_identifier` first.

The model knows nothing of stores or of PDDL text: rules about how items relate live in
:mod:`~merlin2_sailor.knowledge.rules`, and the PDDL text in
:mod:`~merlin2_sailor.knowledge.pddl_writer`.
"""

import math
from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.naming import require_identifier

ROOT_TYPE = "object"
"""PDDL's built-in type: every type derives from it, so it is never stored or deleted."""

DEFAULT_ACTION_DURATION = 10.0
"""KANT's default duration for a durative action, in seconds."""


class Provenance(Enum):
    """Where a fact came from, which decides who may overrule it."""

    PERCEIVED = "perceived"
    """Grounded from an anchor: what the camera sees, which outranks what was expected."""
    EXPECTED = "expected"
    """Announced by an action as its effect: a prediction that perception confirms or retracts."""
    DECLARED = "declared"
    """Stated by a user or a mission: nobody but its author removes it."""


class Timing(Enum):
    """When a condition or effect of a durative action holds, spelled as PDDL spells it."""

    AT_START = "at start"
    AT_END = "at end"
    OVER_ALL = "over all"


def _names(values: Iterable[str], role: str) -> tuple[str, ...]:
    """Accept lists as well as tuples, as KANT does, but store tuples so items stay hashable."""
    if isinstance(values, str):
        raise KnowledgeError(f"{role} must be a sequence of names, got the string {values!r}")
    return tuple(require_identifier(value, role) for value in values)


@dataclass(frozen=True)
class PddlType:
    """A PDDL type; ``supertype`` builds the hierarchy predicates and actions type-check against."""

    name: str
    supertype: str = ROOT_TYPE

    def __post_init__(self) -> None:
        require_identifier(self.name, "type name")
        require_identifier(self.supertype, "supertype name")
        if self.name == ROOT_TYPE:
            raise KnowledgeError(
                f"'{ROOT_TYPE}' is PDDL's built-in root type and cannot be declared; "
                "declare your own type, which derives from it by default"
            )
        if self.name == self.supertype:
            raise KnowledgeError(f"type {self.name!r} cannot be its own supertype")


@dataclass(frozen=True)
class PddlObject:
    """A named thing of one type: an anchored object, a waypoint, the robot."""

    name: str
    type: str

    def __post_init__(self) -> None:
        require_identifier(self.name, "object name")
        require_identifier(self.type, f"type of object {self.name!r}")


@dataclass(frozen=True)
class Predicate:
    """A relation's name and the types of its arguments, in order."""

    name: str
    parameter_types: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        require_identifier(self.name, "predicate name")
        parameter_types = _names(self.parameter_types, f"parameter type of {self.name!r}")
        object.__setattr__(self, "parameter_types", parameter_types)

    @property
    def arity(self) -> int:
        """How many objects a proposition of this predicate takes."""
        return len(self.parameter_types)


PropositionKey = tuple[str, tuple[str, ...], bool]
"""What identifies a proposition: predicate, objects and whether it is a goal."""


@dataclass(frozen=True)
class Proposition:
    """A predicate applied to objects: a fact of the state, or a goal when ``is_goal``.

    ``provenance`` is an attribute, not part of the identity (:attr:`key`): a fact that was
    expected and is then perceived is the same fact, updated.
    """

    predicate: str
    objects: tuple[str, ...] = ()
    is_goal: bool = False
    provenance: Provenance = Provenance.DECLARED

    def __post_init__(self) -> None:
        require_identifier(self.predicate, "predicate name")
        object.__setattr__(self, "objects", _names(self.objects, f"object of {self.predicate!r}"))
        if not isinstance(self.provenance, Provenance):
            raise KnowledgeError(
                f"provenance of {self} must be a Provenance member, got {self.provenance!r}"
            )

    @property
    def key(self) -> PropositionKey:
        """The identity under which a store keeps this proposition."""
        return (self.predicate, self.objects, self.is_goal)

    def __str__(self) -> str:
        text = f"{self.predicate}({', '.join(self.objects)})"
        return f"goal {text}" if self.is_goal else text


@dataclass(frozen=True)
class Parameter:
    """A typed parameter of an action, named without PDDL's leading ``?``."""

    name: str
    type: str = ROOT_TYPE

    def __post_init__(self) -> None:
        require_identifier(self.name, "parameter name")
        require_identifier(self.type, f"type of parameter {self.name!r}")


@dataclass(frozen=True)
class TimedLiteral:
    """A predicate over an action's parameters, possibly negated, at a time of the action.

    ``time`` is None for an instantaneous action and a :class:`Timing` for a durative one; a
    string such as ``"at start"`` is accepted so actions can be written in YAML.
    """

    predicate: str
    arguments: tuple[str, ...] = ()
    time: Timing | None = None
    is_negative: bool = False

    def __post_init__(self) -> None:
        require_identifier(self.predicate, "predicate name")
        arguments = _names(self.arguments, f"argument of {self.predicate!r}")
        object.__setattr__(self, "arguments", arguments)
        if self.time is not None and not isinstance(self.time, Timing):
            try:
                object.__setattr__(self, "time", Timing(self.time))
            except ValueError:
                allowed = ", ".join(repr(timing.value) for timing in Timing)
                raise KnowledgeError(
                    f"unknown time {self.time!r} on {self.predicate!r}; use one of {allowed}"
                ) from None


@dataclass(frozen=True)
class Condition(TimedLiteral):
    """A literal an action requires (to be false when ``is_negative``)."""


@dataclass(frozen=True)
class Effect(TimedLiteral):
    """A literal an action makes true (or false when ``is_negative``); never "over all"."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.time is Timing.OVER_ALL:
            raise KnowledgeError(
                f"effect on {self.predicate!r} cannot happen 'over all'; use 'at start' or 'at end'"
            )


@dataclass(frozen=True)
class PddlAction:
    """A planning operator; MERLIN2 pairs each with a behaviour that carries it out.

    Durative by default with KANT's duration, because MERLIN2's actions take time to run.
    """

    name: str
    parameters: tuple[Parameter, ...] = ()
    conditions: tuple[Condition, ...] = ()
    effects: tuple[Effect, ...] = ()
    durative: bool = True
    duration: float = DEFAULT_ACTION_DURATION

    def __post_init__(self) -> None:
        require_identifier(self.name, "action name")
        for attribute, item_class in (
            ("parameters", Parameter),
            ("conditions", Condition),
            ("effects", Effect),
        ):
            items = tuple(getattr(self, attribute))
            strays = [item for item in items if type(item) is not item_class]
            if strays:
                raise KnowledgeError(
                    f"{attribute} of action {self.name!r} must be {item_class.__name__} items, "
                    f"got {strays!r}"
                )
            object.__setattr__(self, attribute, items)
        names = [parameter.name for parameter in self.parameters]
        duplicates = sorted({name for name in names if names.count(name) > 1})
        if duplicates:
            raise KnowledgeError(f"action {self.name!r} repeats parameter(s) {duplicates}")
        if self.durative and not (math.isfinite(self.duration) and self.duration > 0):
            raise KnowledgeError(
                f"durative action {self.name!r} needs a positive finite duration, "
                f"got {self.duration!r}"
            )
        for literal in (*self.conditions, *self.effects):
            self._check_literal(literal, names)

    def _check_literal(self, literal: TimedLiteral, parameter_names: list[str]) -> None:
        role = "effect" if isinstance(literal, Effect) else "condition"
        unknown = [name for name in literal.arguments if name not in parameter_names]
        if unknown:
            raise KnowledgeError(
                f"{role} {literal.predicate!r} of action {self.name!r} uses {unknown}, "
                f"which are not its parameters {parameter_names}"
            )
        if self.durative and literal.time is None:
            raise KnowledgeError(
                f"{role} {literal.predicate!r} of durative action {self.name!r} needs a time: "
                "'at start', 'at end' or 'over all'"
            )
        if not self.durative and literal.time is not None:
            raise KnowledgeError(
                f"{role} {literal.predicate!r} of instantaneous action {self.name!r} cannot have "
                f"a time ({literal.time.value!r}); drop it or make the action durative"
            )

    def parameter_type(self, parameter_name: str) -> str:
        """The declared type of one of this action's parameters."""
        for parameter in self.parameters:
            if parameter.name == parameter_name:
                return parameter.type
        raise KnowledgeError(f"action {self.name!r} has no parameter {parameter_name!r}")


KnowledgeItem = PddlType | PddlObject | Predicate | Proposition | PddlAction
"""Anything a knowledge base stores."""
