"""The PDDL domain of SAILOR's behaviours, written once, as data.

Names matter: the mission runtime, the demos and the anchoring layer's grounding use them.

Types: ``wp`` (the grounding's location type); anchored objects are of types the grounding
derives from PDDL's root ``object`` (``cup``, ``bottle``...), so every action takes ``object``.

Predicates: ``robot_at(?w - wp)``; ``object_at(?o - object ?w - wp)`` and ``missing(?o - object)``,
written by the anchoring layer's grounding from what the camera sees; ``explored(?w - wp)``;
``robot_near(?o - object)``; ``carried(?o - object)``.

Actions (durative, MERLIN2's default duration):

* ``navigation(?o ?d - wp)``, MERLIN2's own (its signature, parameter names included: origin, destination);
* ``explore(?waypoint - wp)``: look all around a waypoint;
* ``approach_object(?target - object ?waypoint - wp)``: face an object and see it again;
* ``find_object(?target - object ?origin - wp)``: search for a missing object; the robot ends
  wherever it found it, which only the behaviour knows, so it writes ``robot_at`` itself;
* ``bring(?target - object ?origin ?destination - wp)``: pick, carry, place.
"""

from __future__ import annotations

from types import MappingProxyType

from merlin2_sailor.knowledge import Condition, Effect, Parameter, PddlAction, PddlType, Predicate
from merlin2_sailor.knowledge.model import ROOT_TYPE

LOCATION_TYPE = "wp"
OBJECT_TYPE = ROOT_TYPE

ROBOT_AT = "robot_at"
OBJECT_AT = "object_at"
MISSING = "missing"
EXPLORED = "explored"
ROBOT_NEAR = "robot_near"
CARRIED = "carried"

WP_TYPE = PddlType(LOCATION_TYPE)

PREDICATES = MappingProxyType(
    {
        ROBOT_AT: Predicate(ROBOT_AT, (LOCATION_TYPE,)),
        OBJECT_AT: Predicate(OBJECT_AT, (OBJECT_TYPE, LOCATION_TYPE)),
        MISSING: Predicate(MISSING, (OBJECT_TYPE,)),
        EXPLORED: Predicate(EXPLORED, (LOCATION_TYPE,)),
        ROBOT_NEAR: Predicate(ROBOT_NEAR, (OBJECT_TYPE,)),
        CARRIED: Predicate(CARRIED, (OBJECT_TYPE,)),
    }
)

START, END, OVER_ALL = "at start", "at end", "over all"

NAVIGATION_ORIGIN, NAVIGATION_DESTINATION = "o", "d"
"""navigation's parameter names: MERLIN2's own (merlin2_basic_actions), so that SAILOR's navigation
is the same PDDL action as the one it replaces, down to what KANT stores."""

NAVIGATION = PddlAction(
    "navigation",
    (Parameter(NAVIGATION_ORIGIN, LOCATION_TYPE), Parameter(NAVIGATION_DESTINATION, LOCATION_TYPE)),
    (Condition(ROBOT_AT, (NAVIGATION_ORIGIN,), START),),
    (
        Effect(ROBOT_AT, (NAVIGATION_ORIGIN,), START, is_negative=True),
        Effect(ROBOT_AT, (NAVIGATION_DESTINATION,), END),
    ),
)

EXPLORE = PddlAction(
    "explore",
    (Parameter("waypoint", LOCATION_TYPE),),
    (Condition(ROBOT_AT, ("waypoint",), START),),
    (Effect(EXPLORED, ("waypoint",), END),),
)

APPROACH_OBJECT = PddlAction(
    "approach_object",
    (Parameter("target", OBJECT_TYPE), Parameter("waypoint", LOCATION_TYPE)),
    (
        Condition(ROBOT_AT, ("waypoint",), START),
        Condition(OBJECT_AT, ("target", "waypoint"), OVER_ALL),
    ),
    (Effect(ROBOT_NEAR, ("target",), END),),
)

FIND_OBJECT = PddlAction(
    "find_object",
    (Parameter("target", OBJECT_TYPE), Parameter("origin", LOCATION_TYPE)),
    (Condition(ROBOT_AT, ("origin",), START), Condition(MISSING, ("target",), START)),
    (
        Effect(ROBOT_AT, ("origin",), START, is_negative=True),
        Effect(ROBOT_NEAR, ("target",), END),
    ),
)

BRING = PddlAction(
    "bring",
    (
        Parameter("target", OBJECT_TYPE),
        Parameter("origin", LOCATION_TYPE),
        Parameter("destination", LOCATION_TYPE),
    ),
    (
        Condition(ROBOT_AT, ("origin",), START),
        Condition(OBJECT_AT, ("target", "origin"), START),
    ),
    (
        Effect(ROBOT_AT, ("origin",), START, is_negative=True),
        Effect(OBJECT_AT, ("target", "origin"), START, is_negative=True),
        Effect(CARRIED, ("target",), START),
        Effect(ROBOT_AT, ("destination",), END),
        Effect(OBJECT_AT, ("target", "destination"), END),
        Effect(CARRIED, ("target",), END, is_negative=True),
    ),
)

ACTIONS = MappingProxyType(
    {action.name: action for action in (NAVIGATION, EXPLORE, APPROACH_OBJECT, FIND_OBJECT, BRING)}
)


def predicates_of(action: PddlAction) -> tuple[Predicate, ...]:
    """The domain's predicates an action mentions, in the domain's order."""
    used = {literal.predicate for literal in (*action.conditions, *action.effects)}
    return tuple(predicate for name, predicate in PREDICATES.items() if name in used)
