"""Start SAILOR's actions as MERLIN2 actions: ``python -m merlin2_sailor_behaviors.merlin2.run``.

Each named action (all when none is named) becomes a MERLIN2 FSM action node under ``/merlin2``,
registered in MERLIN2's knowledge base and run by MERLIN2's executor; Ctrl-C stops them and
MERLIN2 withdraws the actions. The behaviours' settings are the defaults of
config/behaviors.yaml; give another grounding file with ``--grounding PATH``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from merlin2_sailor.errors import SailorError
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS, select_actions


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("actions", nargs="*", help=f"actions to run, of {list(SAILOR_ACTIONS)} (default: all)")
    parser.add_argument("--grounding", default="", help="grounding YAML with the map (default: config/grounding.yaml)")
    options = parser.parse_args(argv)
    try:
        from merlin2_sailor_behaviors.merlin2.fsm_action import sailor_fsm_action_class

        action_class = sailor_fsm_action_class()
        actions = select_actions(options.actions)
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2

    import rclpy
    from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor

    from merlin2_sailor_behaviors.merlin2.context import ros_context_factory

    rclpy.init()
    nodes: list = []
    executor = MultiThreadedExecutor()
    try:
        make_context = ros_context_factory(options.grounding)
        nodes = [action_class(action, make_context) for action in actions]
        # MERLIN2's nodes (simple_node) spin themselves on executors of their own; a plain rclpy
        # node is spun here.
        for node in nodes:
            if not hasattr(node, "join_spin"):
                executor.add_node(node)
        if executor.get_nodes():
            executor.spin()
        elif nodes:
            nodes[0].join_spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2
    finally:
        executor.shutdown()
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
