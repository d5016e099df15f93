"""Writing an action's effects into the knowledge base, and taking them back.

Provenance of an added fact (the decision, and why):

* a fact about an anchored object (``object_at(cup_3, kitchen)`` after a pick and place) is
  written EXPECTED: it is the action's prediction, which the anchoring layer's Track confirms
  (it becomes PERCEIVED) or contradicts (the sync deletes it). A DECLARED fact would be out of
  perception's reach, so a wrong prediction would never be corrected;
* a fact about nothing anchored (``robot_at(kitchen)``: waypoints are not perceived) is written
  DECLARED, with the runtime as its author: nobody but the runtime removes it.

A fact the knowledge base already holds is left as it is, so an action never downgrades a
PERCEIVED fact to EXPECTED. Deleting effects delete whatever the provenance: the action made the
fact false. What was written is returned, so a failed action's at-start effects can be undone.
"""

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from merlin2_sailor.knowledge import Change, KnowledgeBase, Proposition, Provenance
from merlin2_sailor_behaviors.planning.grounding import GroundLiteral

AnchoredTest = Callable[[str], bool]
"""Whether an object name is an anchored object (one the perception layer grounds)."""

PERCEPTION_PROVENANCES = (Provenance.PERCEIVED, Provenance.EXPECTED)


def anchored_by_provenance(store: KnowledgeBase) -> AnchoredTest:
    """An object is anchored when a fact about it was perceived or expected.

    Waypoints and the robot only ever have declared facts. A deployment that knows its anchored
    types better can pass its own test to the dispatcher instead.
    """

    def is_anchored(object_name: str) -> bool:
        return any(
            not proposition.is_goal and proposition.provenance in PERCEPTION_PROVENANCES
            for proposition in store.propositions_about(object_name)
        )

    return is_anchored


@dataclass(frozen=True)
class AppliedEffects:
    """What one batch of effects changed: facts it added and facts it deleted."""

    added: tuple[Proposition, ...] = ()
    deleted: tuple[Proposition, ...] = ()


class EffectWriter:
    """Applies ground effects to a store as one batch, with the provenance rule above."""

    def __init__(self, store: KnowledgeBase, is_anchored: AnchoredTest) -> None:
        self._store = store
        self._is_anchored = is_anchored
        self._anchored: set[str] = set()

    def remember_anchored(self, object_names: Iterable[str]) -> None:
        """Note which of a step's objects are anchored, before its effects run: an at-start
        effect may delete the very fact (``object_at(cup_1, a)``) that showed it was."""
        self._anchored.update(name for name in object_names if self._is_anchored(name))

    def apply(self, effects: Iterable[GroundLiteral]) -> AppliedEffects:
        """Apply effects in one batch; returns what really changed."""
        added: list[Proposition] = []
        deleted: list[Proposition] = []
        for effect in effects:
            predicate, objects = effect.fact
            stored = self._store.propositions.get((predicate, objects, False))
            if effect.negative and stored is not None:
                deleted.append(stored)
            elif not effect.negative and stored is None:
                anchored = any(
                    name in self._anchored or self._is_anchored(name) for name in objects
                )
                provenance = Provenance.EXPECTED if anchored else Provenance.DECLARED
                added.append(Proposition(predicate, objects, provenance=provenance))
        changes = [Change.delete(p) for p in deleted] + [Change.save(p) for p in added]
        if changes:
            self._store.apply(changes)
        return AppliedEffects(tuple(added), tuple(deleted))

    def undo(self, applied: AppliedEffects) -> None:
        """Take back effects of a step that failed, leaving alone what others changed since
        (a fact naming an object that left the knowledge base meanwhile, an anchor merged or
        forgotten, is not brought back: the store would refuse it, and it would be false)."""
        changes = [
            Change.delete(p)
            for p in applied.added
            if self._store.propositions.get(p.key) == p  # still ours, unchanged
        ] + [
            Change.save(p)
            for p in applied.deleted
            if self._store.propositions.get(p.key) is None
            and all(self._store.objects.get(name) is not None for name in p.objects)
        ]
        if changes:
            self._store.apply(changes)
