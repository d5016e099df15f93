"""MERLIN2's planner node, with KANT's types rooted at ``object`` as PDDL means them.

``python -m merlin2_sailor_behaviors.merlin2.planner --ros-args -p planner:=3``

MERLIN2's PDDL generator lists KANT's types flat, ``object`` among them (KANT has no subtypes, and
MERLIN2 itself declares a type ``object``): ``(:types cup object wp)``. In PDDL every type without
a parent is an ``object``, but unified-planning's reader reads an explicitly declared ``object``
as one more unrelated root type, and its aries engine (up-aries 0.5.0, the temporal engine the
``planner:=3`` unified-planning planner picks here) crashes on an action whose parameters have
two unrelated root types, such as ``find_object(?target - object ?origin - wp)``: no plan, and
the mission aborts. This runs MERLIN2's own planner node, unmodified, and hands its planner the
domain with the types written as PDDL means them (``(:types cup wp - object)``); every planner
MERLIN2 offers reads that the same way.
"""

from __future__ import annotations

import importlib
import re
import sys
from collections.abc import Sequence

from merlin2_sailor.errors import DependencyError

PLANNER_MODULE = "merlin2_planner.merlin2_planner_node"
ROOT_TYPE = "object"
TYPES_SECTION = re.compile(r"\(:types\s+([^()]*)\)", re.IGNORECASE)


def rooted_types(domain: str) -> str:
    """The domain with flat types declared as subtypes of ``object`` (unchanged when they already
    have parents, or when there are none)."""
    match = TYPES_SECTION.search(domain)
    if match is None or "-" in match.group(1).split():
        return domain
    names = [name for name in match.group(1).split() if name != ROOT_TYPE]
    if not names:
        return domain
    section = "(:types\n\t" + "\n\t".join(names) + f" - {ROOT_TYPE}\n)"
    return domain[:match.start()] + section + domain[match.end():]


def main(argv: Sequence[str] | None = None) -> int:
    arguments = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    try:
        planner_node = importlib.import_module(PLANNER_MODULE)
    except ImportError as error:
        message = DependencyError(f"MERLIN2's planner ({PLANNER_MODULE}) is not importable ({error}); "
                                  "build MERLIN2 in a ROS 2 workspace and source it")
        print(f"cannot start: {message}", file=sys.stderr)
        return 2

    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=arguments)
    node = planner_node.Merlin2PlannerNode()
    original = node.planner.generate_plan

    def generate_plan(domain: str, problem: str) -> None:
        original(rooted_types(domain.replace("\\n", "\n").replace("\\t", "\t")), problem)

    node.planner.generate_plan = generate_plan
    node.get_logger().info("KANT's types are handed to the planner rooted at 'object'")
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
