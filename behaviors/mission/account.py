"""The running account of a mission: one line per thing an operator wants to see happen.

The dispatcher logs plans and steps; this module words the rest: facts entering and leaving the
knowledge base (with who vouches for them) and the anchor events that matter to a mission
(acquired, reacquired after being missing, missing, retracted, forgotten). Reacquisitions of
anchors seen a frame ago are routine and are not worded. ROS-free: the node feeds it.
"""

from __future__ import annotations

from collections.abc import Iterable

from merlin2_sailor.knowledge import ChangeEvent, Operation, Proposition

#: Anchor event kinds worth a line, as the anchoring node names them.
NOTABLE_ANCHOR_EVENTS = frozenset({"acquired", "missing", "retracted", "forgotten"})


def describe_fact_changes(events: Iterable[ChangeEvent]) -> list[str]:
    """``+ object_at(cup_2, bedroom)  [perceived]`` / ``- robot_at(kitchen)`` for fact changes.

    Goals, types, predicates and objects are left out: they are the mission's own declarations.
    """
    lines = []
    for event in events:
        item = event.item
        if not isinstance(item, Proposition) or item.is_goal:
            continue
        sign = "+" if event.operation is Operation.SAVE else "-"
        fact = f"{item.predicate}({', '.join(item.objects)})"
        provenance = f"  [{item.provenance.value.lower()}]" if event.operation is Operation.SAVE else ""
        lines.append(f"{sign} {fact}{provenance}")
    return lines


class AnchorEventWording:
    """Words anchor events, keeping in mind which anchors are missing to spot their return."""

    def __init__(self) -> None:
        self._missing: set[str] = set()

    def describe(self, kind: str, symbol: str, class_name: str = "", reason: str = "") -> str | None:
        """A line for a notable event, None for routine ones."""
        kind = kind.lower()
        if kind == "reacquired" or (kind == "confirmed" and symbol in self._missing):
            if symbol in self._missing:
                self._missing.discard(symbol)
                return f"anchor {symbol} reacquired after being missing"
            return None
        if kind == "missing":
            self._missing.add(symbol)
        elif kind == "forgotten":
            self._missing.discard(symbol)
        if kind not in NOTABLE_ANCHOR_EVENTS:
            return None
        what = f" ({class_name})" if class_name else ""
        why = f": {reason}" if reason else ""
        return f"anchor {symbol}{what} {kind}{why}"
