"""approach_object(?target - object ?waypoint - wp): face an object and see it again.

Confirmation by reacquisition: the robot turns to face where the anchor is and succeeds once the
anchoring layer reports the anchor confirmed and seen after the step started, within
``approach_timeout``; otherwise it aborts, saying what the anchor's state was.

1. PREPARING: the anchor now (its position, and when it was last seen: the baseline).
2. FACING: turn in place towards it.
3. WATCHING: ask the anchoring layer until the anchor is seen again.
"""

from __future__ import annotations

from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.domain import APPROACH_OBJECT, WP_TYPE, predicates_of
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.actions.states import (
    BehaviorState,
    CallbackState,
    GoTo,
    Target,
    abort,
    require_anchor,
    robot_pose_or,
    wait_until,
)
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

BASELINE_KEY = "approach_object.baseline"
TARGET_KEY = "approach_object.facing"


def prepare(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    anchor = require_anchor(state.context, symbol)
    blackboard[BASELINE_KEY] = anchor
    robot = robot_pose_or(state.context, blackboard["waypoint"])
    blackboard[TARGET_KEY] = Target(f"a pose facing {symbol}", robot.facing(anchor.position[0], anchor.position[1]))
    return SUCCEED


def watch(state: BehaviorState, blackboard: Blackboard) -> str:
    symbol = blackboard["target"]
    baseline = blackboard[BASELINE_KEY]
    context = state.context
    latest = [baseline]

    def seen() -> bool:
        latest[0] = context.anchoring.get_anchor(symbol)
        return latest[0] is not None and latest[0].seen_since(baseline)

    if wait_until(seen, context.config.approach_timeout, context.config.poll_period, state):
        return SUCCEED
    if state.is_canceled():
        return CANCEL
    now = "no longer anchored" if latest[0] is None else f"{latest[0].state.value}, not seen again"
    return abort(
        blackboard,
        f"{symbol} was not reacquired within {context.config.approach_timeout:g} s while facing it "
        f"at {blackboard['waypoint']}: its anchor is {now}",
    )


def approach_object_state_machine(context: BehaviorContext) -> StateMachine:
    """The approach_object behaviour: reads ``target`` and ``waypoint`` from the blackboard."""
    machine = StateMachine(outcomes=[SUCCEED, ABORT, CANCEL])
    machine.add_state("PREPARING", CallbackState(context, prepare), {SUCCEED: "FACING"})
    machine.add_state("FACING", GoTo(context, TARGET_KEY), {SUCCEED: "WATCHING"})
    machine.add_state("WATCHING", CallbackState(context, watch))
    return machine


APPROACH_OBJECT_ACTION = SailorAction(
    APPROACH_OBJECT, (WP_TYPE,), predicates_of(APPROACH_OBJECT), approach_object_state_machine
)
