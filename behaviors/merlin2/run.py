"""Start SAILOR's actions as MERLIN2 actions: ``python -m merlin2_sailor_behaviors.merlin2.run``.

Each named action (all when none is named) becomes a MERLIN2 FSM action node under ``/merlin2``,
registered in MERLIN2's knowledge base (with its own duration) and run by MERLIN2's executor;
waypoints are driven to through MERLIN2's waypoint navigation where it is installed;
Ctrl-C (or SIGTERM) withdraws every action from the knowledge base once, then exits 0. The
behaviours' settings are the defaults of config/behaviors.yaml; give another grounding file with
``--grounding PATH``.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import time
from collections.abc import Sequence

from rclpy.utilities import remove_ros_args

from merlin2_sailor.errors import SailorError
from merlin2_sailor.ros.navigation_interface import WAYPOINT_NAVIGATION_ACTION
from merlin2_sailor_behaviors.actions.context import BehaviorConfig
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS, select_actions
from merlin2_sailor_behaviors.merlin2.kant import wait_for_kant
from merlin2_sailor_behaviors.merlin2.node_threads import let_node_threads_end, ros_shutdown_ends_node_threads

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
WITHDRAW_SECONDS = 15.0
"""How long withdrawing every action from MERLIN2's knowledge base may take at exit."""
STOP_POLL_SECONDS = 0.2
KANT_WAIT_SECONDS = 60.0
"""How long the actions wait for KANT's node at start (in a launch it may start after them)."""
"""How often the main thread looks for a stop request while the actions run."""


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("actions", nargs="*", help=f"actions to run, of {list(SAILOR_ACTIONS)} (default: all)")
    parser.add_argument("--grounding", default="", help="grounding YAML with the map (default: config/grounding.yaml)")
    parser.add_argument(
        "--waypoint-navigation", default=None, metavar="ACTION",
        help=f"NavigateToWp server to drive to waypoints by name (default: {WAYPOINT_NAVIGATION_ACTION} where "
             "waypoint_navigation_msgs is installed; '' drives to them with NavigateToPose)")
    parser.add_argument("--wait", type=float, default=KANT_WAIT_SECONDS, metavar="SECONDS",
                        help="how long to wait for MERLIN2's knowledge base (KANT's node in /merlin2) to answer "
                             "before registering the actions (default: %(default)s)")
    parser.add_argument("--look-dwell", type=float, default=BehaviorConfig.look_dwell, metavar="SECONDS",
                        help="seconds to stand still after each turn when looking around (default: %(default)s)")
    arguments = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    options = parser.parse_args(remove_ros_args(arguments)[1:])  # --ros-args ... are ROS's
    try:
        from merlin2_sailor_behaviors.merlin2.fsm_action import sailor_fsm_action_class

        action_class = sailor_fsm_action_class()
        actions = select_actions(options.actions)
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2

    import rclpy
    from rclpy.executors import MultiThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    from merlin2_sailor_behaviors.merlin2.context import ros_context_factory

    # Ctrl-C is handled here, not by rclpy: rclpy's handler shuts ROS down at once, and then MERLIN2
    # cannot withdraw the actions from its knowledge base (its DAO call fails on a dead context).
    rclpy.init(args=arguments, signal_handler_options=SignalHandlerOptions.NO)
    stop = StopRequest()
    previous_handlers = {number: signal.signal(number, stop) for number in STOP_SIGNALS}
    nodes: list = []
    executor = MultiThreadedExecutor()
    try:
        wait_for_kant(options.wait)  # MERLIN2 registers each action through KANT's DAOs, which never give up
        make_context = ros_context_factory(
            options.grounding, config=BehaviorConfig(look_dwell=options.look_dwell),
            waypoint_action=options.waypoint_navigation)
        for action in actions:  # one by one, so an interrupted start withdraws those already made
            nodes.append(action_class(action, make_context))
        # MERLIN2's nodes (simple_node) spin themselves on threads of their own; plain rclpy
        # nodes are spun here.
        for node in nodes:
            if not hasattr(node, "join_spin"):
                executor.add_node(node)
        if executor.get_nodes():
            threading.Thread(target=executor.spin, name="sailor-actions", daemon=True).start()
        print(f"running {', '.join(action.name for action in actions)} as MERLIN2 actions; Ctrl-C stops them",
              flush=True)
        stop.running = True
        while not stop.requested:
            time.sleep(STOP_POLL_SECONDS)
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted while starting", file=sys.stderr)
        return 130
    finally:
        withdrawn = withdraw(nodes)
        executor.shutdown()
        with ros_shutdown_ends_node_threads():
            rclpy.try_shutdown()
            let_node_threads_end(nodes)
        for number, handler in previous_handlers.items():
            signal.signal(number, handler)
    return 0 if withdrawn else 1


class StopRequest:
    """The SIGINT / SIGTERM handler: a stop request once the actions run, an interrupt before.

    It only sets a flag, which the main thread polls: a handler that takes a lock (Event.set) can
    deadlock against the main thread holding that very lock when the signal arrives.
    """

    def __init__(self) -> None:
        self.running = False
        self.requested = False

    def __call__(self, signal_number: int, frame: object) -> None:
        if not self.running:
            raise KeyboardInterrupt  # still starting (MERLIN2 may wait for KANT): stop that
        self.requested = True


def withdraw(nodes: Sequence, deadline: float = WITHDRAW_SECONDS) -> bool:
    """Destroy each node once, while ROS is still up, so MERLIN2 withdraws its action from KANT.

    MERLIN2's withdrawal waits on KANT without a deadline; a knowledge base that does not answer
    within ``deadline`` seconds is reported, and the process ends anyway.
    """
    def destroy_all() -> None:
        for node in nodes:
            try:
                node.destroy_node()
            except Exception as error:  # one action's failure must not keep the others registered
                print(f"could not withdraw {node.get_name()}: {error}", file=sys.stderr)
                failures.append(node)

    failures: list = []
    worker = threading.Thread(target=destroy_all, name="sailor-withdraw", daemon=True)
    worker.start()
    worker.join(deadline)
    if worker.is_alive():
        print(f"the knowledge base did not answer within {deadline:g} s: some actions may still be registered",
              file=sys.stderr)
        return False
    return not failures

if __name__ == "__main__":
    raise SystemExit(main())
