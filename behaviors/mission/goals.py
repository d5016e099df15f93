"""Mission goals as people type them: ``robot_near(cup_2)``, ``(robot_near cup_2)`` or ``robot_near cup_2``.

The three spellings are the function-call form the logs print, PDDL's own, and the plain form a
shell makes easiest. Names go through the project's one naming rule, so a goal can only name
what a PDDL identifier can.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import Proposition, Provenance
from merlin2_sailor.knowledge.naming import to_identifier

_CALL = re.compile(r"^\s*([^\s(),]+)\s*\(\s*([^()]*)\)\s*$")
_PDDL = re.compile(r"^\s*\(\s*([^()]*)\)\s*$")


def parse_goal(text: str) -> Proposition:
    """One goal proposition; raises ConfigurationError, naming the text, when it is not one."""
    call = _CALL.match(text)
    if call:
        predicate, arguments = call.group(1), [a for a in re.split(r"[\s,]+", call.group(2)) if a]
    else:
        pddl = _PDDL.match(text)
        words = (pddl.group(1) if pddl else text).split()
        if not words:
            raise ConfigurationError(f"empty goal {text!r}; write it as predicate(object, ...)")
        predicate, arguments = words[0], words[1:]
    names = [predicate, *arguments]
    for name in names:
        if "(" in name or ")" in name or to_identifier(name) != name.lower():
            raise ConfigurationError(
                f"goal {text!r} is not predicate(object, ...) with PDDL names: {name!r} is not a valid name"
            )
    return Proposition(
        predicate.lower(),
        tuple(argument.lower() for argument in arguments),
        is_goal=True,
        provenance=Provenance.DECLARED,
    )


def parse_goals(texts: Iterable[str]) -> tuple[Proposition, ...]:
    """Every goal of a mission, in order; at least one."""
    goals = tuple(parse_goal(text) for text in texts if text.strip())
    if not goals:
        raise ConfigurationError("a mission needs at least one goal, e.g. robot_at(kitchen)")
    return goals
