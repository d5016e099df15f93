"""``sailor anchors``: the live anchors of a running anchoring node, as a table.

It asks the node's ``get_anchors`` service once or (``--watch``) every second until Ctrl-C.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from merlin2_sailor.errors import SailorError

STATE_NAMES = ("tentative", "confirmed", "missing", "forgotten")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "anchors", help="print the live anchors of the anchoring node as a table",
        description="Print the anchors of a running anchoring node (symbol, class, state, "
                    "position, confidence, times seen, last seen).",
    )
    parser.add_argument("--node", default="/anchoring", help="the anchoring node (default /anchoring)")
    parser.add_argument("--class", dest="class_name", default="", help="only anchors of this class")
    parser.add_argument("--watch", action="store_true", help="refresh every second until Ctrl-C")
    parser.add_argument("--timeout", type=float, default=10.0, metavar="SECONDS",
                        help="how long to wait for the node (default 10)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    import rclpy

    from merlin2_sailor_interfaces.srv import GetAnchors

    rclpy.init()
    node = rclpy.create_node("sailor_anchors_cli")
    try:
        client = node.create_client(GetAnchors, f"{arguments.node.rstrip('/')}/get_anchors")
        if not client.wait_for_service(timeout_sec=arguments.timeout):
            raise SailorError(f"no anchoring node answers at {arguments.node} "
                              f"(waited {arguments.timeout:g} s); is it running?")
        while True:
            future = client.call_async(GetAnchors.Request(class_name=arguments.class_name))
            rclpy.spin_until_future_complete(node, future, timeout_sec=arguments.timeout)
            if future.result() is None:
                raise SailorError(f"{arguments.node} did not answer within {arguments.timeout:g} s")
            print(render_table(future.result()), flush=True)
            if not arguments.watch:
                return 0
            time.sleep(1.0)
            print()
    except KeyboardInterrupt:
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def render_table(response: Any) -> str:
    header = (f"{'symbol':<18} {'class':<14} {'state':<10} {'x':>7} {'y':>7} {'z':>6} {'conf':>5} "
              f"{'seen':>5} {'last seen':>12}")
    lines = [f"{len(response.anchors)} anchors in frame '{response.frame_id}'", header, "-" * len(header)]
    for anchor in response.anchors:
        state = STATE_NAMES[anchor.state] if anchor.state < len(STATE_NAMES) else str(anchor.state)
        last_seen = anchor.last_seen.sec + anchor.last_seen.nanosec * 1e-9
        lines.append(
            f"{anchor.symbol:<18} {anchor.class_name:<14} {state:<10} {anchor.position.x:>7.2f} "
            f"{anchor.position.y:>7.2f} {anchor.position.z:>6.2f} {anchor.confidence:>5.2f} "
            f"{anchor.times_seen:>5d} {last_seen:>12.1f}"
        )
    return "\n".join(lines)
