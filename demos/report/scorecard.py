"""Scoring anchors against the world's ground truth: what a user asks of an anchoring system.

Is every object anchored exactly once, where it is, under one symbol the whole run, and does the
knowledge base say where it is? Anchors and true objects are associated by Hungarian assignment
over same-class pairs within ``max_distance`` (scipy), each snapshot on its own; the identity
history then counts how often a true object's symbol changed (an identity switch, as in MOT
metrics: a look-alike taking another's symbol, or an object re-anchored under a new symbol).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

#: Anchor states that claim an object exists (tentative anchors have no symbol in the KB yet).
CLAIMING_STATES = frozenset({"confirmed", "missing"})


@dataclass(frozen=True)
class TrueObject:
    """An object of the simulated world as it really is."""

    id: str
    class_name: str
    position: tuple[float, float, float]
    size: tuple[float, float, float] | None = None
    """Its box's extent along the world's axes (None: not known)."""


@dataclass(frozen=True)
class AnchorRecord:
    """An anchor as the anchoring node reports it."""

    symbol: str
    class_name: str
    position: tuple[float, float, float]
    state: str = "confirmed"
    indistinguishable_from: tuple[str, ...] = ()
    """The anchors the anchoring layer said this one cannot be told from (a search left undecided)."""


def associate(
    truth: Sequence[TrueObject], anchors: Sequence[AnchorRecord], max_distance: float = 0.5
) -> dict[str, str]:
    """True object id -> anchor symbol, one to one, same class, at most ``max_distance`` apart.

    An anchor that sees its object (CONFIRMED) is preferred to a MISSING one within reach: a
    MISSING anchor says its object is not where it stands. The red mug's MISSING anchor, left
    where a green mug was put in its place, was 0.02 m nearer to the green mug than the green mug's
    own anchor and took it by distance alone, and the green mug's anchor counted as a duplicate
    (`replaced_by_another_colour`, network, seed 0, 6 December 2026). A MISSING anchor alone near
    an object still anchors it."""
    if not truth or not anchors:
        return {}
    true_xyz = np.array([obj.position for obj in truth], dtype=float)
    anchor_xyz = np.array([anchor.position for anchor in anchors], dtype=float)
    distance = np.linalg.norm(true_xyz[:, None, :] - anchor_xyz[None, :, :], axis=2)
    same_class = np.array([[obj.class_name == a.class_name for a in anchors] for obj in truth])
    allowed = same_class & (distance <= max_distance)
    missing = np.array([anchor.state == "missing" for anchor in anchors], dtype=bool)
    cost = np.where(allowed, distance + np.where(missing, max_distance, 0.0)[None, :], max_distance * 1e3)
    rows, columns = linear_sum_assignment(cost)
    return {truth[r].id: anchors[c].symbol for r, c in zip(rows, columns, strict=True) if allowed[r, c]}


@dataclass
class IdentityHistory:
    """Which symbol each true object carried over the run; a change of symbol is a switch."""

    last_symbol: dict[str, str] = field(default_factory=dict)
    symbols: dict[str, list[str]] = field(default_factory=dict)
    switches: dict[str, int] = field(default_factory=dict)

    def record(self, association: Mapping[str, str]) -> None:
        """Add one snapshot's association (an object not associated now keeps its last symbol)."""
        for object_id, symbol in association.items():
            previous = self.last_symbol.get(object_id)
            if previous is not None and previous != symbol:
                self.switches[object_id] = self.switches.get(object_id, 0) + 1
            if previous != symbol:
                self.symbols.setdefault(object_id, []).append(symbol)
            self.last_symbol[object_id] = symbol

    @property
    def total_switches(self) -> int:
        return sum(self.switches.values())


@dataclass(frozen=True)
class Scorecard:
    """The figures of one run; :meth:`to_markdown` is what the report prints."""

    objects: int
    anchored: int
    not_anchored: tuple[str, ...]
    duplicates: tuple[str, ...]
    spurious: tuple[str, ...]
    position_errors: Mapping[str, float]
    wrong_positions: tuple[str, ...]
    identity_switches: Mapping[str, int]
    facts_right: int
    facts_wrong: tuple[str, ...]
    position_tolerance: float
    undecided: tuple[str, ...] = ()
    """Missing anchors the anchoring layer said it cannot tell from an anchor of an object in the
    world: a second symbol it knows of and names (the truth it can justify: "one of these two"),
    counted apart from the duplicates it does not know of."""

    @property
    def mean_position_error(self) -> float:
        return float(np.mean(list(self.position_errors.values()))) if self.position_errors else float("nan")

    @property
    def max_position_error(self) -> float:
        return float(max(self.position_errors.values())) if self.position_errors else float("nan")

    @property
    def total_switches(self) -> int:
        return sum(self.identity_switches.values())

    def to_dict(self) -> dict[str, Any]:
        return {
            "objects": self.objects,
            "anchored": self.anchored,
            "not_anchored": list(self.not_anchored),
            "duplicates": list(self.duplicates),
            "undecided": list(self.undecided),
            "spurious": list(self.spurious),
            "mean_position_error_m": self.mean_position_error,
            "max_position_error_m": self.max_position_error,
            "position_errors_m": dict(self.position_errors),
            "wrong_positions": list(self.wrong_positions),
            "identity_switches": dict(self.identity_switches),
            "facts_right": self.facts_right,
            "facts_wrong": list(self.facts_wrong),
            "position_tolerance_m": self.position_tolerance,
        }

    def to_markdown(self) -> str:
        def listed(items: Iterable[str]) -> str:
            items = list(items)
            return ", ".join(items) if items else "none"

        rows = [
            ("objects in the world", str(self.objects)),
            ("anchored (exactly one anchor each)", f"{self.anchored} / {self.objects}"),
            ("not anchored", listed(self.not_anchored)),
            ("duplicate anchors", listed(self.duplicates)),
            ("missing, said to be indistinguishable from another", listed(self.undecided)),
            ("anchors of nothing", listed(self.spurious)),
            ("position error, mean / max", f"{self.mean_position_error:.3f} m / {self.max_position_error:.3f} m"),
            (f"positions off by more than {self.position_tolerance} m", listed(self.wrong_positions)),
            ("identity switches", str(self.total_switches)),
            ("object_at facts right", str(self.facts_right)),
            ("object_at facts wrong", listed(self.facts_wrong)),
        ]
        lines = ["| figure | value |", "| --- | --- |"]
        lines += [f"| {name} | {value} |" for name, value in rows]
        return "\n".join(lines) + "\n"


def score(
    truth: Sequence[TrueObject],
    anchors: Sequence[AnchorRecord],
    facts: Iterable[tuple[str, str]] = (),
    place_of: Callable[[TrueObject], str | None] | None = None,
    history: IdentityHistory | None = None,
    max_distance: float = 0.5,
    position_tolerance: float = 0.3,
    record_final: bool = True,
) -> Scorecard:
    """Score the final anchors (and ``object_at`` facts, as (symbol, place)) against the truth.

    ``place_of`` gives the place the knowledge base should name for a true object (the same
    grounding the anchoring node uses); without it, facts are not scored. Anchors farther than
    ``max_distance`` from their object count as not anchoring it, so a wrong position shows up
    as one object not anchored plus one anchor of nothing. The final association is added to
    ``history`` unless ``record_final`` is False (a caller whose history holds only anchors in
    view: a stale anchor where another object now stands is not a switch).
    """
    claiming = [anchor for anchor in anchors if anchor.state in CLAIMING_STATES]
    association = associate(truth, claiming, max_distance)
    history = history if history is not None else IdentityHistory()
    if record_final:
        history.record(association)
    by_symbol = {anchor.symbol: anchor for anchor in claiming}
    by_id = {obj.id: obj for obj in truth}
    errors = {
        object_id: float(np.linalg.norm(np.subtract(by_symbol[symbol].position, by_id[object_id].position)))
        for object_id, symbol in association.items()
    }
    matched_symbols = set(association.values())
    unmatched = [anchor for anchor in claiming if anchor.symbol not in matched_symbols]
    # The last anchor of an object taken out of the world, MISSING, is the truth ("it is gone"):
    # neither a duplicate nor a spurious anchor. Confirmed, it would still claim the object is there.
    gone = {symbol for object_id, symbol in history.last_symbol.items() if object_id not in by_id}
    duplicates, spurious, undecided = [], [], []
    for anchor in unmatched:
        if anchor.state == "missing" and anchor.symbol in gone:
            continue
        if anchor.state == "missing" and _said_indistinguishable(anchor, by_symbol, matched_symbols):
            undecided.append(anchor.symbol)
            continue
        near_same_class = any(
            obj.class_name == anchor.class_name
            and np.linalg.norm(np.subtract(obj.position, anchor.position)) <= 2 * max_distance
            for obj in truth
        )
        (duplicates if near_same_class else spurious).append(anchor.symbol)
    facts_right, facts_wrong = 0, []
    if place_of is not None:
        object_of_symbol = {symbol: by_id[object_id] for object_id, symbol in association.items()}
        for symbol, place in facts:
            obj = object_of_symbol.get(symbol)
            if obj is not None and place_of(obj) == place:
                facts_right += 1
            else:
                facts_wrong.append(f"object_at({symbol}, {place})")
    return Scorecard(
        objects=len(truth),
        anchored=len(association),
        not_anchored=tuple(sorted(obj.id for obj in truth if obj.id not in association)),
        duplicates=tuple(sorted(duplicates)),
        spurious=tuple(sorted(spurious)),
        undecided=tuple(sorted(undecided)),
        position_errors=errors,
        wrong_positions=tuple(sorted(i for i, e in errors.items() if e > position_tolerance)),
        identity_switches={i: n for i, n in history.switches.items() if n},
        facts_right=facts_right,
        facts_wrong=tuple(facts_wrong),
        position_tolerance=position_tolerance,
    )


def _said_indistinguishable(anchor: AnchorRecord, by_symbol: Mapping[str, AnchorRecord], matched: set[str]) -> bool:
    """Whether ``anchor`` is one the anchoring layer left undecided: missing and named as not to be
    told from an anchor of its class that stands for an object of the world.

    Twins found where the camera never looked cannot be told apart by any evidence, and the robot
    says so rather than guess, so the sought anchor stays missing beside its candidate's: a doubt
    stated, not an object silently anchored twice. A named partner that anchors nothing,
    or of another class, does not excuse it.
    """
    return any(symbol in matched and by_symbol[symbol].class_name == anchor.class_name
               for symbol in anchor.indistinguishable_from)
