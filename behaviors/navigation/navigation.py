"""navigation(?o ?d - wp): MERLIN2's navigation (from o, the origin, to d, the destination), telling
perception what to expect.

1. PLANNING_ROUTE: the destination's pose from the map (its heading, else the way the robot
   arrives), and, before leaving, the objects the knowledge base places there.
2. NAVIGATING: one NavigateToPose goal; cancelling the action cancels the goal.
3. ANNOUNCING: on arrival, EXPECT_AT for each of those objects at its anchor's current position
   (place = destination, source = "navigation"), so Track checks them against what it sees.
4. LOOKING_AROUND: turn in place through 360 degrees, so each is confirmed or marked missing;
   skipped when nothing was announced (a first visit: exploring is the explore action's job).

It succeeds once arrived: an object the knowledge base cannot list or the anchoring layer cannot
hear about, or a turn that fails, is a warning, not a failed navigation (the robot is there).
"""

from __future__ import annotations

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.domain import NAVIGATION, NAVIGATION_DESTINATION, WP_TYPE, predicates_of
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.robot_location import objects_at
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.actions.states import (
    BehaviorState,
    CallbackState,
    GoTo,
    LookAround,
    place_target,
    warn,
)
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

NAVIGATION_SOURCE = "navigation"
"""The ``source`` of the expectations navigation announces."""

LOOK = "look"
"""ANNOUNCING's outcome when it announced something the camera must now check."""

TARGET_KEY = "navigation.target"
EXPECTED_KEY = "navigation.expected_objects"


def plan_route(state: BehaviorState, blackboard: Blackboard) -> str:
    destination = blackboard[NAVIGATION_DESTINATION]
    blackboard[TARGET_KEY] = place_target(state.context, destination)
    try:
        blackboard[EXPECTED_KEY] = objects_at(state.context.store, destination)
    except KnowledgeError as error:
        blackboard[EXPECTED_KEY] = ()
        warn(state.context, blackboard, f"cannot read what is at {destination}, announcing nothing: {error}")
    return SUCCEED


def announce_expected(state: BehaviorState, blackboard: Blackboard) -> str:
    """EXPECT_AT, at their anchors' positions, for the objects the knowledge base put here."""
    destination = blackboard[NAVIGATION_DESTINATION]
    symbols = blackboard[EXPECTED_KEY]
    if not symbols:
        return SUCCEED  # nothing to check: done
    context = state.context
    try:
        anchors = {anchor.symbol: anchor for anchor in context.anchoring.get_anchors()}
    except BehaviorError as error:
        warn(context, blackboard, f"cannot announce {list(symbols)} at {destination}: {error}")
        return SUCCEED
    for symbol in symbols:
        anchor = anchors.get(symbol)
        if anchor is None:
            context.log("debug", f"{symbol} is at {destination} in the knowledge base but not anchored")
            continue
        try:
            context.anchoring.expect_at(symbol, anchor.position, destination, NAVIGATION_SOURCE)
        except BehaviorError as error:
            warn(context, blackboard, f"cannot announce {symbol} at {destination}: {error}")
    return LOOK


def navigation_state_machine(context: BehaviorContext) -> StateMachine:
    """The navigation behaviour: reads the destination (``d``) from the blackboard."""
    machine = StateMachine(outcomes=[SUCCEED, ABORT, CANCEL])
    machine.add_state("PLANNING_ROUTE", CallbackState(context, plan_route), {SUCCEED: "NAVIGATING"})
    machine.add_state("NAVIGATING", GoTo(context, TARGET_KEY), {SUCCEED: "ANNOUNCING"})
    machine.add_state(
        "ANNOUNCING",
        CallbackState(context, announce_expected, (LOOK, SUCCEED, ABORT, CANCEL)),
        {LOOK: "LOOKING_AROUND"},
    )
    machine.add_state("LOOKING_AROUND", LookAround(context, TARGET_KEY, required=False))
    return machine


NAVIGATION_ACTION = SailorAction(NAVIGATION, (WP_TYPE,), predicates_of(NAVIGATION), navigation_state_machine)
