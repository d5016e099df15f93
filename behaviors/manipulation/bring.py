"""bring(?target - object ?origin ?destination - wp): pick an object, carry it, put it down.

1. PREPARING: the anchor (where the object is, its class) and the destination's pose.
2. FACING_OBJECT: turn towards it.
3. PICKING: Grasp PICK of the anchor's class at the anchor's position.
4. EXPECTING_CARRIED: EXPECT_CARRIED (``carry_offset`` from the robot's base), so Track moves
   the anchor with the robot while the camera cannot see it.
5. CARRYING: navigate to the destination.
6. PLACING: Grasp PLACE ``place_distance`` in front of the robot, at the height it was picked.
7. EXPECTING_AT: EXPECT_AT where it was put (place = destination).
8. CONFIRMING: look at it for up to ``confirm_timeout`` for perception to confirm it; the object
   is down either way, so not seeing it is a warning (the anchoring layer then retracts the
   EXPECTED ``object_at`` the dispatcher wrote, and a mission replans).

A failed pick, drive or place aborts with the reason; expectations the anchoring layer cannot
take are warnings (the object is moved all the same).
"""

from __future__ import annotations

from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.domain import BRING, WP_TYPE, predicates_of
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.actions.states import (
    BehaviorState,
    CallbackState,
    GoTo,
    Target,
    abort,
    place_target,
    require_anchor,
    robot_pose_or,
    wait_until,
    warn,
)
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

BRING_SOURCE = "bring"
"""The ``source`` of the expectations bring announces."""

ANCHOR_KEY = "bring.anchor"
FACING_KEY = "bring.facing"
DESTINATION_KEY = "bring.destination"
PLACED_KEY = "bring.placed_at"
BASELINE_KEY = "bring.baseline"


def prepare(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    anchor = require_anchor(state.context, symbol)
    blackboard[ANCHOR_KEY] = anchor
    robot = robot_pose_or(state.context, blackboard["origin"])
    blackboard[FACING_KEY] = Target(f"a pose facing {symbol}", robot.facing(anchor.position[0], anchor.position[1]))
    blackboard[DESTINATION_KEY] = place_target(state.context, blackboard["destination"])
    return SUCCEED


def pick(state: BehaviorState, blackboard: Blackboard) -> str:
    anchor = blackboard[ANCHOR_KEY]
    result = state.context.grasp.pick(anchor.class_name, anchor.position)
    if not result.success:
        x, y, z = anchor.position
        return abort(
            blackboard,
            f"could not pick {anchor.symbol} ({anchor.class_name}) at ({x:.2f}, {y:.2f}, {z:.2f}): "
            f"{result.message or 'the gripper gave no reason'}",
        )
    return SUCCEED


def expect_carried(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    try:
        state.context.anchoring.expect_carried(symbol, state.context.config.carry_offset, BRING_SOURCE)
    except BehaviorError as error:
        warn(state.context, blackboard, f"cannot announce that {symbol} is carried: {error}")
    return SUCCEED


def place(state: BehaviorState, blackboard: Blackboard) -> str:
    anchor = blackboard[ANCHOR_KEY]
    destination = blackboard["destination"]
    robot = state.context.navigation.robot_pose() or blackboard[DESTINATION_KEY].pose
    x, y = robot.ahead(state.context.config.place_distance)
    point = (x, y, anchor.position[2])
    result = state.context.grasp.place(point)
    if not result.success:
        return abort(
            blackboard,
            f"could not place {anchor.symbol} at {destination} ({x:.2f}, {y:.2f}, {point[2]:.2f}): "
            f"{result.message or 'the gripper gave no reason'}",
        )
    blackboard[PLACED_KEY] = point
    return SUCCEED


def expect_placed(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    destination = blackboard["destination"]
    anchoring = state.context.anchoring
    try:
        blackboard[BASELINE_KEY] = anchoring.get_anchor(symbol)
        anchoring.expect_at(symbol, blackboard[PLACED_KEY], destination, BRING_SOURCE)
    except BehaviorError as error:
        warn(state.context, blackboard, f"cannot announce {symbol} at {destination}: {error}")
    return SUCCEED


def confirm(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    context = state.context
    baseline = blackboard[BASELINE_KEY] if BASELINE_KEY in blackboard else None

    def seen() -> bool:
        anchor = context.anchoring.get_anchor(symbol)
        return anchor is not None and anchor.seen_since(baseline)

    try:
        confirmed = wait_until(seen, context.config.confirm_timeout, context.config.poll_period, state)
    except BehaviorError as error:
        warn(context, blackboard, f"cannot check that {symbol} was seen where it was put: {error}")
        return SUCCEED
    if state.is_canceled():
        return CANCEL
    if not confirmed:
        warn(
            context,
            blackboard,
            f"{symbol} was put down at {blackboard['destination']} but not seen there within "
            f"{context.config.confirm_timeout:g} s",
        )
    return SUCCEED


def bring_state_machine(context: BehaviorContext) -> StateMachine:
    """The bring behaviour: reads ``target``, ``origin`` and ``destination``."""
    machine = StateMachine(outcomes=[SUCCEED, ABORT, CANCEL])
    machine.add_state("PREPARING", CallbackState(context, prepare), {SUCCEED: "FACING_OBJECT"})
    machine.add_state("FACING_OBJECT", GoTo(context, FACING_KEY), {SUCCEED: "PICKING"})
    machine.add_state("PICKING", CallbackState(context, pick), {SUCCEED: "EXPECTING_CARRIED"})
    machine.add_state("EXPECTING_CARRIED", CallbackState(context, expect_carried), {SUCCEED: "CARRYING"})
    machine.add_state("CARRYING", GoTo(context, DESTINATION_KEY), {SUCCEED: "PLACING"})
    machine.add_state("PLACING", CallbackState(context, place), {SUCCEED: "EXPECTING_AT"})
    machine.add_state("EXPECTING_AT", CallbackState(context, expect_placed), {SUCCEED: "CONFIRMING"})
    machine.add_state("CONFIRMING", CallbackState(context, confirm))
    return machine


BRING_ACTION = SailorAction(BRING, (WP_TYPE,), predicates_of(BRING), bring_state_machine)
