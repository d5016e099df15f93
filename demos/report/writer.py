"""Writing the mission demo's report folder from plain data: scorecard, map, PDDL, account, summary."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from merlin2_sailor_demos.report.scorecard import (
    AnchorRecord,
    IdentityHistory,
    Scorecard,
    TrueObject,
    associate,
    score,
)
from merlin2_sailor_demos.report.top_down_map import MapLayers, draw_map
from merlin2_sailor_demos.report.verdict import Verdict, judge


@dataclass(frozen=True)
class DemoOutcome:
    """What the demo set out to show, and whether it did."""

    missions: Sequence[tuple[str, bool, str]]
    """(name, succeeded, reason) of each mission, in order."""
    target: str
    target_symbol: str
    target_found: bool
    target_error: float
    seconds: float

    @property
    def succeeded(self) -> bool:
        return all(ok for _, ok, _ in self.missions) and self.target_found


def explain_duplicates(duplicates: Sequence[str], anchors: Sequence[AnchorRecord], associated: set[str],
                       acquired_because: Mapping[str, str]) -> dict[str, str]:
    """symbol -> where the duplicate came from: its state, why it was anchored anew, and the same-class
    anchor nearest to it that does anchor an object (the other half of the pair), with why *that*
    one was anchored anew: of two anchors of one object, either may be the one a wrong decision made."""
    by_symbol = {anchor.symbol: anchor for anchor in anchors}

    def because(symbol: str) -> str:
        return acquired_because.get(symbol) or "no anchor of its class within the matching gate"

    origins: dict[str, str] = {}
    for symbol in duplicates:
        duplicate = by_symbol.get(symbol)
        if duplicate is None:
            continue
        text = f"{symbol} ({duplicate.state}), anchored anew: {because(symbol)}"
        others = [anchor for anchor in anchors if anchor.symbol in associated
                  and anchor.class_name == duplicate.class_name]
        if others:
            other = min(others, key=lambda anchor: math.dist(anchor.position, duplicate.position))
            text += (f"; beside {other.symbol} ({other.state}, {math.dist(other.position, duplicate.position):.2f} m), "
                     f"anchored anew: {because(other.symbol)}")
        origins[symbol] = text
    return origins


def truth_from_ground_truth(data: dict[str, Any]) -> list[TrueObject]:
    """True objects from the world node's ground_truth.json (carried objects left out)."""
    return [
        TrueObject(obj["id"], obj["class"], tuple(obj["position"]),
                   tuple(obj["size"]) if obj.get("size") is not None else None)
        for obj in data.get("objects", [])
        if not obj.get("carried")
    ]


def write_report(
    folder: Path,
    truth: Sequence[TrueObject],
    anchors: Sequence[AnchorRecord],
    facts: Sequence[tuple[str, str]],
    place_of: Callable[[TrueObject], str | None],
    layers: MapLayers,
    history: IdentityHistory,
    pddl: str,
    account: Sequence[str],
    outcome: DemoOutcome,
    claims: Mapping[str, Any],
    acquired_because: Mapping[str, str] | None = None,
) -> tuple[Scorecard, Verdict]:
    """Write every file of the report; return the scorecard and the verdict on the ``claims``
    (the section :func:`verdict.judge` reads; the identity history is the caller's, so the final
    snapshot is not added to it here). ``acquired_because``: symbol -> why the anchoring node
    made it a new anchor (its acquired event), to say where each duplicate came from."""
    folder.mkdir(parents=True, exist_ok=True)
    card = score(truth, anchors, facts, place_of, history, record_final=False)
    association = associate(truth, [a for a in anchors if a.state in ("confirmed", "missing")])
    origins = explain_duplicates(card.duplicates, anchors, set(association.values()), acquired_because or {})
    draw_map(folder / "map.png", layers, truth, anchors, association,
             title=f"SAILOR mission demo: {len(anchors)} anchors, {len(truth)} objects")
    (folder / "knowledge.pddl").write_text(pddl)
    (folder / "account.log").write_text("\n".join(account) + "\n")
    data: dict[str, Any] = {
        **card.to_dict(), "identity_history": history.symbols, "outcome": {
            "succeeded": outcome.succeeded, "missions": [list(m) for m in outcome.missions],
            "target": outcome.target, "target_symbol": outcome.target_symbol,
            "target_found": outcome.target_found, "target_error_m": outcome.target_error,
            "seconds": outcome.seconds},
        "claims": dict(claims), "duplicate_origins": origins}
    verdict = judge(data)
    data["verdict"] = verdict.as_dict()
    (folder / "scorecard.json").write_text(json.dumps(data, indent=2))
    lines = [
        "# SAILOR mission demo",
        "",
        f"Result: **{'succeeded' if outcome.succeeded else 'failed'}** in {outcome.seconds:.0f} s.",
        "",
        "| mission | outcome | why |",
        "| --- | --- | --- |",
        *(f"| {name} | {'succeeded' if ok else 'failed'} | {reason} |" for name, ok, reason in outcome.missions),
        "",
        f"The {outcome.target.replace('_', ' ')} was anchored as `{outcome.target_symbol}`; after the world moved it, "
        + (f"it was found again under the same symbol, {outcome.target_error:.2f} m from where it really is."
           if outcome.target_found else "it was not found again under that symbol."),
        "",
        "## Scorecard against the world's ground truth",
        "",
        card.to_markdown(),
        *([f"Duplicate {origin}." for origin in verdict.duplicate_origins] + [""] if verdict.duplicate_origins else []),
        "## The mission's claim against the ground truth",
        "",
        f"Outcome: {verdict.outcome}; **{'right' if verdict.right else 'wrong'}**"
        + (": " + "; ".join(verdict.problems) + "." if verdict.problems else "."),
        "",
        "Files: `map.png` (top-down: true objects in green, anchors as crosses), `frames/` (camera frames with "
        "the anchors' boxes and symbols), `knowledge.pddl` (the final knowledge base), `account.log`, "
        "`scorecard.json`.",
        "",
    ]
    (folder / "summary.md").write_text("\n".join(lines))
    return card, verdict
