"""PDDL text from the knowledge model: the only code in the package that writes PDDL.

Every name reaching this module has already been validated by the model (see
:mod:`~merlin2_sailor.knowledge.naming`), so the writer can assemble text without quoting and
without any way for a name to change the file's structure. Output is sorted, so the same
knowledge always gives the same bytes, which keeps diffs and planner caches meaningful.
"""

from collections import defaultdict
from collections.abc import Iterable
from decimal import Decimal

from merlin2_sailor.knowledge.model import (
    ROOT_TYPE,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    TimedLiteral,
)
from merlin2_sailor.knowledge.naming import require_identifier
from merlin2_sailor.knowledge.store import KnowledgeBase

DEFAULT_DOMAIN_NAME = "merlin2"
DEFAULT_PROBLEM_NAME = "merlin2_problem"
_INDENT = "  "


def domain_text(
    name: str,
    types: Iterable[PddlType],
    predicates: Iterable[Predicate],
    actions: Iterable[PddlAction],
) -> str:
    """A PDDL domain declaring the given types, predicates and actions."""
    require_identifier(name, "domain name")
    actions = sorted(actions, key=lambda action: action.name)
    lines = [f"(define (domain {name})", f"{_INDENT}(:requirements {_requirements(actions)})"]
    lines += _section("types", _type_lines(types))
    lines += _section(
        "predicates",
        [_predicate_declaration(p) for p in sorted(predicates, key=lambda p: p.name)],
    )
    for action in actions:
        lines += _action_lines(action)
    lines.append(")")
    return "\n".join(lines) + "\n"


def problem_text(
    name: str,
    domain_name: str,
    objects: Iterable[PddlObject],
    propositions: Iterable[Proposition],
) -> str:
    """A PDDL problem: the objects, the facts as its initial state, the goals as its goal."""
    require_identifier(name, "problem name")
    require_identifier(domain_name, "domain name")
    facts: list[str] = []
    goals: list[str] = []
    for proposition in propositions:
        (goals if proposition.is_goal else facts).append(
            _atom(proposition.predicate, proposition.objects)
        )
    names_by_type: dict[str, list[str]] = defaultdict(list)
    for pddl_object in objects:
        names_by_type[pddl_object.type].append(pddl_object.name)
    object_lines = [
        f"{' '.join(sorted(names))} - {type_name}"
        for type_name, names in sorted(names_by_type.items())
    ]
    lines = [f"(define (problem {name})", f"{_INDENT}(:domain {domain_name})"]
    lines += _section("objects", object_lines)
    lines += _section("init", sorted(facts))
    lines += [
        f"{_INDENT}(:goal (and",
        *(_INDENT * 2 + goal for goal in sorted(goals)),
        f"{_INDENT}))",
    ]
    lines.append(")")
    return "\n".join(lines) + "\n"


def domain_from_store(store: KnowledgeBase, name: str = DEFAULT_DOMAIN_NAME) -> str:
    """The domain of everything a knowledge base holds."""
    return domain_text(
        name, store.types.get_all(), store.predicates.get_all(), store.actions.get_all()
    )


def problem_from_store(
    store: KnowledgeBase,
    name: str = DEFAULT_PROBLEM_NAME,
    domain_name: str = DEFAULT_DOMAIN_NAME,
) -> str:
    """The problem of a knowledge base's objects, facts and goals."""
    return problem_text(name, domain_name, store.objects.get_all(), store.propositions.get_all())


def _section(keyword: str, lines: list[str]) -> list[str]:
    return [f"{_INDENT}(:{keyword}", *(_INDENT * 2 + line for line in lines), f"{_INDENT})"]


def _requirements(actions: list[PddlAction]) -> str:
    requirements = [":typing"]
    if any(action.durative for action in actions):
        requirements.append(":durative-actions")
    if any(literal.is_negative for action in actions for literal in action.conditions):
        requirements.append(":negative-preconditions")
    return " ".join(requirements)


def _type_lines(types: Iterable[PddlType]) -> list[str]:
    names_by_supertype: dict[str, list[str]] = defaultdict(list)
    for pddl_type in types:
        names_by_supertype[pddl_type.supertype].append(pddl_type.name)
    return [
        f"{' '.join(sorted(names))} - {supertype}"
        for supertype, names in sorted(
            names_by_supertype.items(), key=lambda item: (item[0] != ROOT_TYPE, item[0])
        )
    ]


def _predicate_declaration(predicate: Predicate) -> str:
    parameters = [
        f"?argument{position} - {type_name}"
        for position, type_name in enumerate(predicate.parameter_types, 1)
    ]
    return f"({' '.join([predicate.name, *parameters])})"


def _atom(predicate: str, arguments: Iterable[str]) -> str:
    return f"({' '.join([predicate, *arguments])})"


def _literal(literal: TimedLiteral) -> str:
    text = _atom(literal.predicate, (f"?{argument}" for argument in literal.arguments))
    if literal.is_negative:
        text = f"(not {text})"
    if literal.time is not None:
        text = f"({literal.time.value} {text})"
    return text


def _conjunction(keyword: str, literals: Iterable[TimedLiteral]) -> list[str]:
    return [
        f"{_INDENT * 2}:{keyword} (and",
        *(_INDENT * 3 + _literal(literal) for literal in literals),
        f"{_INDENT * 2})",
    ]


def _action_lines(action: PddlAction) -> list[str]:
    parameters = " ".join(f"?{p.name} - {p.type}" for p in action.parameters)
    if action.durative:
        duration = format(Decimal(repr(float(action.duration))), "f")
        return [
            f"{_INDENT}(:durative-action {action.name}",
            f"{_INDENT * 2}:parameters ({parameters})",
            f"{_INDENT * 2}:duration (= ?duration {duration})",
            *_conjunction("condition", action.conditions),
            *_conjunction("effect", action.effects),
            f"{_INDENT})",
        ]
    return [
        f"{_INDENT}(:action {action.name}",
        f"{_INDENT * 2}:parameters ({parameters})",
        *_conjunction("precondition", action.conditions),
        *_conjunction("effect", action.effects),
        f"{_INDENT})",
    ]
