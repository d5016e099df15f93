"""explore(?waypoint - wp): look all around a waypoint, so everything there gets anchored.

1. PREPARING: the waypoint's position, starting from the robot's current heading. When the
   robot looked all around right here moments ago (navigation does on arrival when it expects
   anchored objects there), that look counts: done, without turning through 360 degrees again.
2. LOOKING_AROUND: turn in place through 360 degrees (a failed turn aborts: looking is the
   whole point of this action).
"""

from __future__ import annotations

from merlin2_sailor_behaviors.actions.clients import Pose2D
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.domain import EXPLORE, WP_TYPE, predicates_of
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.actions.states import BASIC, BehaviorState, CallbackState, LookAround, Target
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

TARGET_KEY = "explore.target"
ALREADY_LOOKED = "already_looked"


def prepare(state: BehaviorState, blackboard: Blackboard) -> str:
    waypoint = blackboard["waypoint"]
    context = state.context
    place = context.places.get(waypoint)
    robot = context.navigation.robot_pose()
    if robot is not None and context.config.look_fresh_for > 0.0:
        look = context.looks.recent(waypoint, robot.x, robot.y, context.config.look_fresh_for)
        if look is not None:
            context.log("info", f"explore({waypoint}): looked all around here on arrival; not again")
            return ALREADY_LOOKED
    yaw = robot.yaw if robot is not None else (place.yaw or 0.0)
    blackboard[TARGET_KEY] = Target(waypoint, Pose2D(place.x, place.y, yaw))
    return SUCCEED


def explore_state_machine(context: BehaviorContext) -> StateMachine:
    """The explore behaviour: reads ``waypoint`` from the blackboard."""
    machine = StateMachine(outcomes=[SUCCEED, ABORT, CANCEL])
    machine.add_state("PREPARING", CallbackState(context, prepare, outcomes=[*BASIC, ALREADY_LOOKED]),
                      {SUCCEED: "LOOKING_AROUND", ALREADY_LOOKED: SUCCEED})
    machine.add_state("LOOKING_AROUND", LookAround(context, TARGET_KEY, required=True))
    return machine


EXPLORE_ACTION = SailorAction(EXPLORE, (WP_TYPE,), predicates_of(EXPLORE), explore_state_machine)
