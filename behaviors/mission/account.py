"""The running account of a mission: one line per thing an operator wants to see happen.

The dispatcher logs plans and steps; this module words the rest: facts entering and leaving the
knowledge base (with who vouches for them) and the anchor events that matter to a mission: an
anchor confirmed (a new object the robot now knows), missing, reacquired after being missing,
retracted, forgotten. What flickers with every glance is left out: tentative anchors (most are a
detector's false positives), reacquisitions of anchors seen a frame ago, and the ``visible`` /
``seen`` / size facts. ROS-free: the node feeds it.
"""

from __future__ import annotations

from collections.abc import Iterable

from merlin2_sailor.knowledge import ChangeEvent, Operation, Proposition

#: Facts that change with every glance of the camera: not worth a line each.
QUIET_PREDICATES = frozenset({"visible", "seen", "small", "medium", "large"})


def describe_fact_changes(
    events: Iterable[ChangeEvent], quiet_predicates: frozenset[str] = QUIET_PREDICATES
) -> list[str]:
    """``+ object_at(cup_2, bedroom)  [perceived]`` / ``- robot_at(kitchen)`` for fact changes.

    Goals, types, predicates and objects are left out: they are the mission's own declarations.
    """
    lines = []
    for event in events:
        item = event.item
        if not isinstance(item, Proposition) or item.is_goal or item.predicate in quiet_predicates:
            continue
        sign = "+" if event.operation is Operation.SAVE else "-"
        fact = f"{item.predicate}({', '.join(item.objects)})"
        provenance = f"  [{item.provenance.value.lower()}]" if event.operation is Operation.SAVE else ""
        lines.append(f"{sign} {fact}{provenance}")
    return lines


class AnchorEventWording:
    """Words anchor events, remembering which anchors were confirmed and which are missing."""

    def __init__(self) -> None:
        self._confirmed: set[str] = set()
        self._missing: set[str] = set()

    def describe(self, kind: str, symbol: str, class_name: str = "", reason: str = "") -> str | None:
        """A line for a notable event, None for routine ones."""
        kind = kind.lower()
        what = f" ({class_name})" if class_name else ""
        why = f": {reason}" if reason else ""
        if symbol in self._missing and kind == "confirmed":
            if reason == "expectation":
                return f"anchor {symbol}{what} seen where it was searched for"
            self._missing.discard(symbol)
            return f"anchor {symbol}{what} reacquired after being missing"
        if kind == "reacquired":
            return None  # routine, or a first sighting of a missing anchor: not back until confirmed
        if kind == "confirmed":
            if symbol in self._confirmed:
                return f"anchor {symbol}{what} confirmed where expected" if reason == "expectation" else None
            self._confirmed.add(symbol)
            return f"anchor {symbol}{what} anchored"
        if kind == "missing":
            self._missing.add(symbol)
            return f"anchor {symbol}{what} missing"
        if kind == "retracted":
            return f"anchor {symbol}{what} retracted{why}"
        if kind == "ambiguous":
            return f"anchor {symbol}{what} identity unknown{why}"
        if kind == "forgotten" and symbol in self._confirmed:
            self._confirmed.discard(symbol)
            self._missing.discard(symbol)
            return f"anchor {symbol}{what} forgotten{why}"
        return None  # acquired (tentative), routine reacquisitions, forgetting never-confirmed anchors
