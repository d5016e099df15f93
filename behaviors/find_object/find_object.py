"""find_object(?target - object ?origin - wp): SAILOR's top-down Find, as a state machine.

Given an object's symbol (``target``), or, outside PDDL, a detector class (``class_name`` on the
blackboard), the robot searches for it:

1. PLANNING_SEARCH: ask the anchoring layer where it was last anchored (``find_anchor``); the
   search visits the waypoint nearest that place first, then every other waypoint, each next
   stop the nearest to the last (with no anchor, starting from the waypoint nearest the robot).
2. For each stop: GOING_TO_STOP, EXPECTING (EXPECT_AT for the sought symbol: at the place it
   was last anchored, exactly; at any other stop, as a search within ``search_radius`` of it, so
   the anchoring layer may take a percept of its class anywhere there as the sought anchor,
   though never one that a look-alike anchored there explains better), LOOKING_AROUND (stops
   early on a reacquisition) and CHECKING (wait up to ``reacquire_timeout`` for the anchor to
   be confirmed and seen since the search began; not found: the search expectation is cleared,
   so the anchor goes back to where it was last perceived). An anchor seen since the search
   began (on the way, from afar) is not announced anywhere, and the next stop is the waypoint
   nearest where it was seen, once, reached facing where it was seen (as the stop where it was
   last anchored is): the search ends there, not wherever the robot happened to be.
3. On success the robot stays at that stop, and the behaviour writes ``robot_at(<stop>)``
   (DECLARED) in the knowledge base itself: the dispatcher only knows ``origin``. The anchored
   facts (``object_at``, ``missing``) are perception's to update.
4. Not found anywhere, or found only among look-alikes the anchoring layer cannot tell apart (the
   anchor reports ``indistinguishable_from``; the search then ends, since guessing would put the
   wrong object under the symbol): RETURNING to ``origin`` (so the ``robot_at(origin)`` the dispatcher
   restores after an abort is true; ``return_on_failure``), then GIVING_UP: aborted, naming
   every stop searched. A stop the robot cannot reach is a warning and the search goes on.
5. Found by look alone: a search may find, where the camera had never watched before, an object
   that looks like the sought one (the anchor reports ``found_by_look_alone``). It may be the
   sought object, moved there, or a copy of it that stood there all along, and the look cannot
   tell: the anchoring layer does not take it, the sought anchor stays missing, and the search
   records the candidate (and the waypoint nearest it) and goes on through the remaining stops.
   A copy seen at a later stop makes the two indistinguishable: the search ends as in 4. Only
   when every stop has been searched and no other copy turned up anywhere searched does it take
   the candidate: PLANNING_CONCLUSION, GOING_TO_CANDIDATE (its waypoint, facing it), CONCLUDING
   (``conclude_search``, then wait up to ``reacquire_timeout`` for the sought anchor to be
   reacquired) and success there as in 3. Refused, not reacquired in time, or the candidate's
   waypoint unreachable: as in 4. A search for a class has no anchor to conclude on.
6. Found nowhere, with no candidate: the search still concludes (``conclude_search``) before it
   gives up, and the anchoring layer reports the sought anchor indistinguishable from anchors the
   search could not rule out, if any (of its colour, looking like it, possible by time and place):
   the search then ends as in 4, "cannot be told from", rather than "not found". Where one anchor
   alone is left in question and no copy of the sought one is anchored, the anchoring layer
   reports it found by look alone instead, and the search goes to it and concludes as in 5.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from merlin2_sailor_behaviors.actions.clients import AnchorReport, Pose2D
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.domain import FIND_OBJECT, WP_TYPE, predicates_of
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.keys import CLASS_NAME_KEY, FOUND_AT_KEY, FOUND_SYMBOL_KEY
from merlin2_sailor_behaviors.actions.robot_location import declare_robot_at
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.actions.states import (
    BehaviorState,
    CallbackState,
    GoTo,
    LookAround,
    Target,
    abort,
    place_target,
    wait_until,
    warn,
)
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

FIND_SOURCE = "find_object"
"""The ``source`` of the expectations find_object announces."""

NEXT = "next"
EXHAUSTED = "exhausted"
NOT_HERE = "not_here"
UNREACHABLE = "unreachable"

SEARCH_KEY = "find_object.search"
STOP_KEY = "find_object.stop"
TARGET_KEY = "find_object.target"
RETURN_KEY = "find_object.return"


@dataclass
class Search:
    """What is sought, where it was last anchored, the stops, and progress through them."""

    symbol: str
    class_name: str
    last_seen: AnchorReport | None
    """The anchor as find_anchor reported it when the search began (None: nothing anchored)."""
    last_place: str | None
    stops: list[str]
    baselines: dict[str, AnchorReport] = field(default_factory=dict)
    """Each candidate anchor as it was when the search began: a sighting must be newer."""
    next_stop: int = 0
    unreachable: list[str] = field(default_factory=list)
    sighted: list[str] = field(default_factory=list)
    """Waypoints driven to because the sought anchor was seen near them, each once (an anchor on
    the line between two waypoints' areas must not send the robot back and forth)."""
    indistinguishable_from: tuple[str, ...] = ()
    """Anchors the anchoring layer found and cannot tell from the sought one (look-alikes): the
    search ends there, unsuccessful, rather than claim one of them is it."""
    look_alone: str = ""
    """The anchor a search found that looks like the sought one, where the camera had never watched
    before (``found_by_look_alone``): taken only once every stop is searched and no copy turned up."""
    look_alone_at: str | None = None
    """The waypoint nearest that candidate, where the search concludes (None: not known)."""

    @property
    def sought(self) -> str:
        return self.symbol or f"an object of class {self.class_name!r}"


def plan_search(state: BehaviorState, blackboard: Blackboard) -> str:
    context = state.context
    symbol = str(blackboard["target"]) if "target" in blackboard else ""
    class_name = str(blackboard[CLASS_NAME_KEY]) if CLASS_NAME_KEY in blackboard else ""
    if not symbol and not class_name:
        return abort(blackboard, f"find_object needs a 'target' symbol or a '{CLASS_NAME_KEY}' on the blackboard")
    robot = context.navigation.robot_pose()
    if symbol:
        anchor = context.anchoring.find_anchor(symbol=symbol)
        if anchor is None:
            return abort(
                blackboard,
                f"the anchoring layer has no anchor {symbol!r} to find: it was never anchored or has been forgotten",
            )
        baselines = {symbol: anchor}
    else:
        near = None if robot is None else (robot.x, robot.y, 0.0)
        anchor = context.anchoring.find_anchor(class_name=class_name, near=near)
        baselines = {report.symbol: report for report in context.anchoring.get_anchors(class_name)}
    last_place = None if anchor is None else context.places.nearest_waypoint(anchor.position[0], anchor.position[1])
    waypoints = context.places.waypoint_names()
    if not waypoints:
        return abort(blackboard, "the map (grounding configuration) has no waypoint to search")
    start = last_place
    if start is None and robot is not None:
        start = context.places.nearest_waypoint(robot.x, robot.y)
    if start is None and "origin" in blackboard and blackboard["origin"] in waypoints:
        start = blackboard["origin"]
    stops = context.places.tour(start or waypoints[0], waypoints)
    search = Search(symbol, class_name, anchor, last_place, stops, baselines)
    blackboard[SEARCH_KEY] = search
    context.log("info", f"searching for {search.sought} at {', '.join(stops)}")
    return SUCCEED


def seen_at(context: BehaviorContext, search: Search) -> str | None:
    """The reachable waypoint nearest the sought anchor, if the camera has seen it since the search
    began (on the way, from afar: a relocation while the robot drove past), else None."""
    return sighting_waypoint(context, search, reacquired(context, search))


def sighting_waypoint(context: BehaviorContext, search: Search, anchor: AnchorReport | None) -> str | None:
    """:func:`seen_at` for an anchor already asked for (None: not seen since the search began)."""
    if anchor is None:
        return None
    place = context.places.nearest_waypoint(anchor.position[0], anchor.position[1])
    return None if place is None or place in search.unreachable or place in search.sighted else place


def next_stop(state: BehaviorState, blackboard: Blackboard) -> str:
    search: Search = blackboard[SEARCH_KEY]
    if search.indistinguishable_from:
        return EXHAUSTED
    sighting = reacquired(state.context, search)
    stop = sighting_waypoint(state.context, search, sighting)  # seen on the way: go where it is
    look_at = None
    if stop is not None:
        search.sighted.append(stop)
        look_at = sighting
    else:
        if search.next_stop >= len(search.stops):
            return EXHAUSTED
        stop = search.stops[search.next_stop]
        search.next_stop += 1
        if stop == search.last_place:
            look_at = search.last_seen
    target = place_target(state.context, stop)
    place = state.context.places.get(stop)
    if look_at is not None and place.yaw is None:
        # Arrive facing where the object was last seen: it is the first thing the camera sees. A
        # waypoint driven to because it was seen from afar needs it most: the bicycle wheeled beside
        # the living room's waypoint, seen from the kitchen, was behind the robot on arrival, not seen
        # there, and the search gave up (scenario suite, `large_object_wheeled_away`, 6 December 2026).
        facing = target.pose.facing(look_at.position[0], look_at.position[1])
        target = Target(stop, Pose2D(target.pose.x, target.pose.y, facing.yaw))
    blackboard[STOP_KEY] = stop
    blackboard[TARGET_KEY] = target
    return NEXT


def note_unreachable(state: BehaviorState, blackboard: Blackboard) -> str:
    search: Search = blackboard[SEARCH_KEY]
    search.unreachable.append(blackboard[STOP_KEY])
    return SUCCEED


def expect_here(state: BehaviorState, blackboard: Blackboard) -> str:
    """EXPECT_AT for the sought symbol at this stop: at its last position when this is the place
    it was last anchored, else at the stop's point (at the height it was last seen)."""
    search: Search = blackboard[SEARCH_KEY]
    if not search.symbol:
        return SUCCEED  # a class has no anchor to move; any new anchor of it will do
    stop = blackboard[STOP_KEY]
    anchor = reacquired(state.context, search)
    if anchor is not None and (
            stop in search.sighted or sighting_waypoint(state.context, search, anchor) not in (None, stop)):
        return SUCCEED  # seen since the search began, by another waypoint or sent here: announcing it would move it
    last = search.last_seen
    radius = 0.0
    if last is not None and stop == search.last_place:
        position = last.position
    else:
        place = state.context.places.get(stop)
        position = (place.x, place.y, last.position[2] if last is not None else 0.0)
        radius = state.context.config.search_radius
    try:
        state.context.anchoring.expect_at(search.symbol, position, stop, FIND_SOURCE, radius)
    except BehaviorError as error:
        warn(state.context, blackboard, f"cannot announce {search.symbol} at {stop}: {error}")
    return SUCCEED


def reacquired(context: BehaviorContext, search: Search) -> AnchorReport | None:
    """The sought anchor if it has been confirmed and seen since the search began."""
    if search.symbol:
        anchor = context.anchoring.get_anchor(search.symbol)
        baseline = search.baselines.get(search.symbol)
        return anchor if anchor is not None and anchor.seen_since(baseline) else None
    candidates = [
        anchor
        for anchor in context.anchoring.get_anchors(search.class_name)
        if anchor.seen_since(search.baselines.get(anchor.symbol))
    ]
    return max(candidates, key=lambda anchor: (anchor.last_seen, anchor.symbol), default=None)


def wait_for_sighting(state: BehaviorState, search: Search) -> AnchorReport | None:
    """The sought anchor once it is confirmed and seen since the search began, waiting up to
    ``reacquire_timeout``; None when it was not (or the wait was cancelled)."""
    context = state.context
    found: list[AnchorReport] = []

    def seen() -> bool:
        anchor = reacquired(context, search)
        if anchor is not None:
            found.append(anchor)
        return anchor is not None

    if wait_until(seen, context.config.reacquire_timeout, context.config.poll_period, state):
        return found[-1]
    return None


def check_here(state: BehaviorState, blackboard: Blackboard) -> str:
    context = state.context
    search: Search = blackboard[SEARCH_KEY]
    stop = blackboard[STOP_KEY]
    found = wait_for_sighting(state, search)
    if found is not None:
        elsewhere = seen_at(context, search)
        if elsewhere not in (None, stop):
            # Seen from here, but by another waypoint (the red mug, re-found in the bedroom while the
            # robot drove to the hall, was reported "found at hall": test_mission_end_to_end).
            context.log("info", f"{search.sought} was seen nearer {elsewhere}: going there")
            return NOT_HERE
    else:
        if search.symbol:
            try:
                context.anchoring.clear_expectation(search.symbol, FIND_SOURCE)
            except BehaviorError as error:
                warn(context, blackboard, f"cannot withdraw the search for {search.symbol} at {stop}: {error}")
        if state.is_canceled():
            return CANCEL
        sought = context.anchoring.get_anchor(search.symbol) if search.symbol else None
        if note_indistinguishable(context, search, sought):
            return NOT_HERE
        note_look_alone(context, search, sought)
        context.log("info", f"{search.sought} is not at {stop}")
        return NOT_HERE
    return found_here(state, blackboard, found)


def found_here(state: BehaviorState, blackboard: Blackboard, anchor: AnchorReport) -> str:
    """The search ends at this stop: the robot is declared here and the find recorded."""
    stop = blackboard[STOP_KEY]
    declare_robot_at(state.context.store, stop)
    blackboard[FOUND_SYMBOL_KEY] = anchor.symbol
    blackboard[FOUND_AT_KEY] = stop
    state.context.log("info", f"found {anchor.symbol} at {stop}")
    return SUCCEED


def note_indistinguishable(context: BehaviorContext, search: Search, sought: AnchorReport | None) -> bool:
    """Whether the sought anchor is reported indistinguishable from look-alikes (then recorded, so
    the search gives up saying so)."""
    if sought is None or not sought.indistinguishable_from:
        return False
    search.indistinguishable_from = sought.indistinguishable_from
    context.log("warning", f"{search.sought}: cannot tell it from {', '.join(sought.indistinguishable_from)} "
                           "(they look alike); its identity is unknown")
    return True


def note_look_alone(context: BehaviorContext, search: Search, sought: AnchorReport | None,
                    why: str = "where the camera had never looked before: a copy may have stood there all along; "
                               "looking at the remaining stops before taking it") -> None:
    """Record the candidate the sought anchor reports found by look alone, and the waypoint nearest
    it, once: the search goes on, since a copy may have stood there all along (``why``: what the
    log line says of it)."""
    if sought is None or not sought.found_by_look_alone or sought.found_by_look_alone == search.look_alone:
        return
    search.look_alone = sought.found_by_look_alone
    candidate = context.anchoring.get_anchor(search.look_alone)
    search.look_alone_at = None if candidate is None else context.places.nearest_waypoint(
        candidate.position[0], candidate.position[1])
    where = search.look_alone_at or "an unknown place"
    context.log("info", f"{search.symbol} looks like {search.look_alone} at {where}, {why}")


def plan_conclusion(state: BehaviorState, blackboard: Blackboard) -> str:
    """Every stop searched: drive to the candidate found by look alone, if the sought anchor still
    reports it and no copy turned up; else EXHAUSTED (the search gives up)."""
    context = state.context
    search: Search = blackboard[SEARCH_KEY]
    if not search.symbol or search.indistinguishable_from:
        return EXHAUSTED
    sought = context.anchoring.get_anchor(search.symbol)
    if note_indistinguishable(context, search, sought):
        return EXHAUSTED
    note_look_alone(context, search, sought)
    if not search.look_alone:
        ask_what_is_left_in_question(context, search)
        if search.indistinguishable_from:
            return EXHAUSTED
        sought = context.anchoring.get_anchor(search.symbol)
        note_look_alone(context, search, sought, "the only anchor the search left in question")
        if not search.look_alone:
            return EXHAUSTED
    if sought is None or sought.found_by_look_alone != search.look_alone:
        context.log("info", f"{search.look_alone} is no longer taken for {search.symbol}: not concluding on it")
        return EXHAUSTED
    candidate = context.anchoring.get_anchor(search.look_alone)
    stop = search.look_alone_at if candidate is None else context.places.nearest_waypoint(
        candidate.position[0], candidate.position[1])
    if candidate is None or stop is None:
        context.log("info", f"{search.look_alone}, which looks like {search.symbol}, is nowhere on the map: "
                            "not concluding on it")
        return EXHAUSTED
    search.look_alone_at = stop
    target = place_target(context, stop)
    if context.places.get(stop).yaw is None:
        facing = target.pose.facing(candidate.position[0], candidate.position[1])
        target = Target(stop, Pose2D(target.pose.x, target.pose.y, facing.yaw))  # as next_stop faces a sighting
    blackboard[STOP_KEY] = stop
    blackboard[TARGET_KEY] = target
    context.log("info", f"no other copy of {search.symbol} anywhere searched: going back to {search.look_alone} "
                        f"at {stop} to take it")
    return NEXT


def ask_what_is_left_in_question(context: BehaviorContext, search: Search) -> None:
    """Found nowhere: before saying "not found", conclude the search with the anchoring layer, which
    reports the sought anchor indistinguishable from anchors the search could not rule out (of its
    colour, looking like it, possible by time and place) rather than absent, or, where one alone is
    left in question and no copy of the sought one is anchored, reports it found by look alone (the
    search then goes to it and concludes there)."""
    try:
        context.anchoring.conclude_search(search.symbol, FIND_SOURCE)
    except BehaviorError as error:
        context.log("warning", f"cannot conclude the search for {search.symbol}: {error}")
        return
    note_indistinguishable(context, search, context.anchoring.get_anchor(search.symbol))


def conclude(state: BehaviorState, blackboard: Blackboard) -> str:
    """At the candidate: ask the anchoring layer to take it for the sought anchor, and wait for the
    sought anchor to be reacquired; NOT_HERE when it was not (the search gives up)."""
    context = state.context
    search: Search = blackboard[SEARCH_KEY]
    stop = blackboard[STOP_KEY]
    try:
        taken = context.anchoring.conclude_search(search.symbol, FIND_SOURCE)
    except BehaviorError as error:
        warn(context, blackboard, f"cannot conclude the search for {search.symbol} on {search.look_alone}: {error}")
        return NOT_HERE
    found = wait_for_sighting(state, search) if taken else None
    if found is not None:
        return found_here(state, blackboard, found)
    if state.is_canceled():
        return CANCEL
    if note_indistinguishable(context, search, context.anchoring.get_anchor(search.symbol)):
        return NOT_HERE
    why = "the anchoring layer did not take it" if not taken else "it was not reacquired in time"
    context.log("info", f"{search.look_alone} at {stop} is not taken for {search.symbol}: {why}")
    return NOT_HERE


def plan_return(state: BehaviorState, blackboard: Blackboard) -> str:
    """Head back to ``origin`` when configured to and it is known; else give up where we are."""
    origin = blackboard["origin"] if "origin" in blackboard else ""
    if not state.context.config.return_on_failure or origin not in state.context.places.names():
        return EXHAUSTED
    blackboard[RETURN_KEY] = place_target(state.context, origin)
    return NEXT


def give_up(state: BehaviorState, blackboard: Blackboard) -> str:
    search: Search = blackboard[SEARCH_KEY]
    searched = [stop for stop in search.stops if stop not in search.unreachable]
    message = f"{search.sought} was not found at {', '.join(searched) or 'any stop'}"
    if search.indistinguishable_from:
        others = ", ".join(search.indistinguishable_from)
        message = f"{search.sought} cannot be told from {others} (they look alike): its identity is unknown"
    if search.unreachable:
        message += f" (could not reach {', '.join(search.unreachable)})"
    return abort(blackboard, message)


def note_failed_return(state: BehaviorState, blackboard: Blackboard) -> str:
    warn(state.context, blackboard, f"could not drive back to {blackboard['origin']} after the search")
    return SUCCEED


def find_object_state_machine(context: BehaviorContext) -> StateMachine:
    """The find_object behaviour: reads ``target`` (or ``class_name``) and ``origin``."""
    machine = StateMachine(outcomes=[SUCCEED, ABORT, CANCEL])
    machine.add_state("PLANNING_SEARCH", CallbackState(context, plan_search), {SUCCEED: "NEXT_STOP"})
    machine.add_state(
        "NEXT_STOP",
        CallbackState(context, next_stop, (NEXT, EXHAUSTED, ABORT, CANCEL)),
        {NEXT: "GOING_TO_STOP", EXHAUSTED: "PLANNING_CONCLUSION"},
    )
    machine.add_state(
        "GOING_TO_STOP",
        GoTo(context, TARGET_KEY, failed_outcome=UNREACHABLE),
        {SUCCEED: "EXPECTING", UNREACHABLE: "NOTING_UNREACHABLE"},
    )
    machine.add_state("NOTING_UNREACHABLE", CallbackState(context, note_unreachable), {SUCCEED: "NEXT_STOP"})
    machine.add_state("EXPECTING", CallbackState(context, expect_here), {SUCCEED: "LOOKING_AROUND"})
    machine.add_state(
        "LOOKING_AROUND",
        LookAround(
            context,
            TARGET_KEY,
            required=False,
            stop_when=lambda blackboard: reacquired(context, blackboard[SEARCH_KEY]) is not None,
        ),
        {SUCCEED: "CHECKING"},
    )
    machine.add_state(
        "CHECKING",
        CallbackState(context, check_here, (SUCCEED, NOT_HERE, ABORT, CANCEL)),
        {NOT_HERE: "NEXT_STOP"},
    )
    machine.add_state(
        "PLANNING_CONCLUSION",
        CallbackState(context, plan_conclusion, (NEXT, EXHAUSTED, ABORT, CANCEL)),
        {NEXT: "GOING_TO_CANDIDATE", EXHAUSTED: "RETURNING_HOME"},
    )
    machine.add_state(
        "GOING_TO_CANDIDATE",
        GoTo(context, TARGET_KEY, failed_outcome=UNREACHABLE),
        {SUCCEED: "CONCLUDING", UNREACHABLE: "RETURNING_HOME"},
    )
    machine.add_state(
        "CONCLUDING",
        CallbackState(context, conclude, (SUCCEED, NOT_HERE, ABORT, CANCEL)),
        {NOT_HERE: "RETURNING_HOME"},
    )
    machine.add_state(
        "RETURNING_HOME",
        CallbackState(context, plan_return, (NEXT, EXHAUSTED, ABORT, CANCEL)),
        {NEXT: "RETURNING", EXHAUSTED: "GIVING_UP"},
    )
    machine.add_state(
        "RETURNING",
        GoTo(context, RETURN_KEY, failed_outcome=UNREACHABLE),
        {SUCCEED: "GIVING_UP", UNREACHABLE: "NOTING_FAILED_RETURN"},
    )
    machine.add_state(
        "NOTING_FAILED_RETURN", CallbackState(context, note_failed_return), {SUCCEED: "GIVING_UP"}
    )
    machine.add_state("GIVING_UP", CallbackState(context, give_up))
    return machine


FIND_OBJECT_ACTION = SailorAction(FIND_OBJECT, (WP_TYPE,), predicates_of(FIND_OBJECT), find_object_state_machine)
