"""Was the mission's claim true? The verdict of one scenario run, from its scorecard alone.

A mission that "succeeds" on the wrong object is wrong, whatever it says. The mission demo
writes a ``claims`` section into scorecard.json (the target, the symbol it had before the
change, what every symbol refers to by its anchor's last sighting, the ``object_at`` facts, the
find mission's result and the scenario's expectation); :func:`judge` reads only that JSON, so a
run can be judged again later, and the judgement tested on synthetic scorecards.

Outcomes: ``found as <symbol>`` (the find mission succeeded), ``unknown`` (it failed saying it
cannot tell the candidates apart, in its reason or by an ``ambiguous`` anchor event about the
target), ``not found`` (it failed otherwise), ``not run`` (the story failed before the find).
The verdict is right when every claim is true:

- expected found: found, the symbol refers to the target, and the knowledge base places it where
  it is; ``unknown`` is right only where the scenario allows it (true twins), and then only if
  the symbol was given to no other object;
- expected not found (removed): not reported found, the symbol given to no other object, and no
  ``object_at`` left for it;
- every ``keep_symbols`` object ends under the symbol it had, every ``new_symbols`` object under
  a symbol no object had before, every ``anchored_once`` object with exactly one anchor;
- no anchor of one object was merged into another object's, in any scenario
  (:mod:`.merges`: the ``merges`` the demo recorded, each with the objects its two anchors were
  first the anchors of).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from merlin2_sailor_demos.report.merges import MergeRecord
from merlin2_sailor_demos.world.mission import Expectation, ExpectedOutcome

#: How a failed find says the evidence cannot choose between candidates ("cup_3 cannot be told
#: from cup_7, cup_14"); an ``ambiguous`` anchor event about the target says the same.
CANNOT_TELL_APART = re.compile(r"cannot (tell|be told)", re.IGNORECASE)

FOUND = "found"
UNKNOWN = "unknown"
NOT_FOUND = "not found"
NOT_RUN = "not run"


@dataclass(frozen=True)
class Verdict:
    """One run judged: its outcome, right or not (and why not), and the scorecard's figures."""

    outcome: str
    right: bool
    problems: tuple[str, ...] = ()
    duplicates: int = 0
    identity_switches: int = 0
    seconds: float = 0.0
    claimed: str | None = None
    """The object the target's symbol refers to at the end (None: none)."""
    duplicate_origins: tuple[str, ...] = ()
    """Each duplicate anchor and where it came from: why it, and the anchor of the object it stands
    beside, were anchored anew (the anchoring node's acquired events), a duplicate's first question."""
    undecided: int = 0
    """Missing anchors left beside the anchor they were said not to be told from (not duplicates)."""

    def as_dict(self) -> dict[str, Any]:
        return {"outcome": self.outcome, "right": self.right, "problems": list(self.problems),
                "duplicates": self.duplicates, "undecided": self.undecided, "identity_switches": self.identity_switches,
                "seconds": round(self.seconds, 1), "claimed": self.claimed,
                "duplicate_origins": list(self.duplicate_origins)}


@dataclass(frozen=True)
class Claims:
    """The ``claims`` section of a scorecard, read and checked."""

    target: str
    target_symbol: str
    target_place: str | None
    symbols_before: Mapping[str, str]
    refers_to: Mapping[str, str | None]
    last_seen: Mapping[str, float]
    object_at: Mapping[str, tuple[str, ...]]
    fetch_ran: bool
    fetch_succeeded: bool
    fetch_reason: str
    expect: Expectation = field(default_factory=Expectation)
    ambiguous: tuple[Mapping[str, Any], ...] = ()
    """The anchoring layer's ``ambiguous`` events (symbol, stamp, details), every symbol's."""
    merges: tuple[MergeRecord, ...] = ()
    """Every anchor forgotten into another, with the objects the two were first the anchors of (:mod:`.merges`)."""

    @classmethod
    def from_scorecard(cls, card: Mapping[str, Any]) -> Claims:
        try:
            data = card["claims"]
            fetch = data["fetch"]
            expect = data.get("expect") or {}
            return cls(
                str(data["target"]), str(data.get("target_symbol") or ""), data.get("target_place"),
                dict(data.get("symbols_before") or {}), dict(data.get("refers_to") or {}),
                {k: float(v) for k, v in (data.get("last_seen") or {}).items()},
                {k: tuple(v) for k, v in (data.get("object_at") or {}).items()},
                bool(fetch["ran"]), bool(fetch["succeeded"]), str(fetch.get("reason", "")),
                Expectation.from_mapping(expect, "claims.expect"),
                tuple(data.get("ambiguous") or ()),
                tuple(MergeRecord.from_mapping(merge) for merge in data.get("merges") or ()),
            )
        except (KeyError, TypeError, AttributeError) as error:
            raise ValueError(f"the scorecard has no usable 'claims' section ({error!r}); was it written by "
                             "the mission demo of this version?") from error

    def current_symbol(self, object_id: str) -> str | None:
        """The symbol ``object_id`` goes by at the end: the most recently seen anchor referring to it."""
        symbols = [symbol for symbol, obj in self.refers_to.items() if obj == object_id]
        return max(symbols, key=lambda symbol: self.last_seen.get(symbol, 0.0), default=None)


def judge(card: Mapping[str, Any], expect: Expectation | None = None) -> Verdict:
    """The verdict of a run from its scorecard.json; ``expect`` overrides the one it records."""
    claims = Claims.from_scorecard(card)
    expect = expect or claims.expect
    outcome = _outcome(claims)
    symbol, target = claims.target_symbol, claims.target
    claimed = claims.refers_to.get(symbol) if symbol else None
    places = claims.object_at.get(symbol, ()) if symbol else ()
    problems: list[str] = []
    if outcome == NOT_RUN:
        problems.append(f"the find mission did not run: {claims.fetch_reason}")
    elif expect.outcome is ExpectedOutcome.FOUND:
        problems += _judge_found(claims, outcome, claimed, places, expect)
    else:
        if outcome == FOUND:
            problems.append(f"reported found as {symbol}, but the {target} was removed"
                            + (f" ({symbol} refers to {claimed})" if claimed not in (None, target) else ""))
        elif outcome == UNKNOWN and not expect.unknown_allowed:
            problems.append("said it cannot tell candidates apart, where the object is simply gone")
        if outcome != FOUND and claimed not in (None, target):
            problems.append(f"{symbol} was given to {claimed}")
        if places:
            problems.append(f"the knowledge base places the removed {target}: "
                            + ", ".join(f"object_at({symbol}, {place})" for place in places))
    problems += _judge_symbols(claims, expect)
    problems += [merge.problem() for merge in claims.merges if merge.wrong]
    scorecard_switches = card.get("identity_switches") or {}
    return Verdict(
        outcome=f"{FOUND} as {symbol}" if outcome == FOUND else outcome,
        right=not problems,
        problems=tuple(problems),
        duplicates=len(card.get("duplicates") or ()),
        undecided=len(card.get("undecided") or ()),
        identity_switches=sum(int(n) for n in scorecard_switches.values()),
        seconds=float((card.get("outcome") or {}).get("seconds", 0.0)),
        claimed=claimed,
        duplicate_origins=duplicate_origins(card),
    )


def duplicate_origins(card: Mapping[str, Any]) -> tuple[str, ...]:
    """Where each duplicate of a scorecard.json came from (:func:`.writer.explain_duplicates`); a
    duplicate without it (a scorecard written before it was recorded) is named with "origin unknown"."""
    origins = card.get("duplicate_origins") or {}
    return tuple(origins.get(symbol) or f"{symbol}: origin unknown" for symbol in card.get("duplicates") or ())


def _outcome(claims: Claims) -> str:
    if not claims.fetch_ran:
        return NOT_RUN
    if claims.fetch_succeeded:
        return FOUND
    said = CANNOT_TELL_APART.search(claims.fetch_reason) or any(
        event.get("symbol") == claims.target_symbol for event in claims.ambiguous)
    return UNKNOWN if said else NOT_FOUND


def _judge_found(claims: Claims, outcome: str, claimed: str | None, places: tuple[str, ...],
                 expect: Expectation) -> list[str]:
    symbol, target = claims.target_symbol, claims.target
    problems = []
    if outcome == FOUND:
        if claimed != target:
            problems.append(f"claimed {symbol}, which refers to {claimed or 'no object'}, not the {target}")
        if tuple(places) != (claims.target_place,):
            said = ", ".join(places) or "nowhere"
            problems.append(f"the knowledge base places {symbol} at {said}; the {target} is at "
                            f"{claims.target_place}")
        return problems
    if outcome == UNKNOWN and not expect.unknown_allowed:
        problems.append("said it cannot tell candidates apart, where the evidence decides")
    elif outcome == NOT_FOUND:
        problems.append(f"not found, though the {target} is in the house"
                        + (f" ({claims.fetch_reason})" if claims.fetch_reason else ""))
    if claimed not in (None, target):
        problems.append(f"{symbol} was given to {claimed}")
    wrong_places = [place for place in places if place != claims.target_place]
    if wrong_places:
        problems.append(f"the knowledge base places {symbol} at {', '.join(wrong_places)}; the {target} is at "
                        f"{claims.target_place}")
    return problems


def _judge_symbols(claims: Claims, expect: Expectation) -> list[str]:
    problems = []
    before = claims.symbols_before
    for object_id in expect.keep_symbols:
        current = claims.current_symbol(object_id)
        if object_id not in before:
            problems.append(f"{object_id} was not anchored before the change")
        elif current != before[object_id]:
            problems.append(f"{object_id} went from {before[object_id]} to {current or 'no symbol'}")
    owners = {symbol: object_id for object_id, symbol in before.items()}
    for object_id in expect.new_symbols:
        current = claims.current_symbol(object_id)
        if current is None:
            problems.append(f"{object_id} was never anchored")
        elif current in owners:
            problems.append(f"{object_id} took {current}, the symbol of {owners[current]}")
    for object_id in expect.anchored_once:
        count = sum(1 for obj in claims.refers_to.values() if obj == object_id)
        if count != 1:
            problems.append(f"{object_id} has {count} anchors")
    return problems
