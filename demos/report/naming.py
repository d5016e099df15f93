"""Which symbol each object of the world had when the robot had looked around: the user pointing.

The verdict asks whether the target's symbol still names the target after the world changed, so
the demo names every object before the change, from the anchors the anchoring node reported. The
rules here are the ones a person pointing at the objects would follow, written once so they can be
tested without a running graph:

- an object is named by the anchor standing where the object was put at the start; confirmed
  anchors are the fresher evidence, and a ``missing`` anchor still names what the robot saw there
  (on a loaded machine an anchor can be missing for three frames just as the look ends);
- only the target, and only when no anchor stands where it was put, is named where it stands now:
  the world may move it while the camera watches, before the look ends, and its anchor then
  followed it. Confirmed or missing, like above: the anchor that followed it may be missing for a
  moment too. An object moved unseen keeps the name of the anchor where it was.
"""

from __future__ import annotations

from collections.abc import Sequence

from merlin2_sailor_demos.report.scorecard import CLAIMING_STATES, AnchorRecord, TrueObject, associate


def symbols_before_change(
    initial_truth: Sequence[TrueObject], target_now: TrueObject | None, anchors: Sequence[AnchorRecord]
) -> dict[str, str]:
    """True object id -> the symbol that named it once the robot had looked around (see the module)."""
    confirmed = [anchor for anchor in anchors if anchor.state == "confirmed"]
    missing = [anchor for anchor in anchors if anchor.state in CLAIMING_STATES and anchor.state != "confirmed"]
    named = _confirmed_first(initial_truth, confirmed, missing)
    if target_now is not None and target_now.id not in named:
        taken = set(named.values())
        named.update(_confirmed_first([target_now], [a for a in confirmed if a.symbol not in taken],
                                      [a for a in missing if a.symbol not in taken]))
    return named


def _confirmed_first(objects: Sequence[TrueObject], confirmed: Sequence[AnchorRecord],
                     missing: Sequence[AnchorRecord]) -> dict[str, str]:
    """Objects named by confirmed anchors, then the rest by missing ones."""
    named = associate(objects, confirmed)
    named.update(associate([obj for obj in objects if obj.id not in named], missing))
    return named
