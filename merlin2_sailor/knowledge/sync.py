"""Keeping a knowledge base up to date with the anchors, by diff and in one batch per call.

The perception node calls :meth:`KnowledgeSync.sync` with the anchors of a frame, off its hot
path. The sync compares them with what it wrote last time and with what it has heard from the
store since, and sends only the difference, as one :meth:`KnowledgeBase.apply` call. It never
reads the store while syncing, so the store may be a remote KB node behind ROS services.

Who may change what:

* the sync creates, and on forgetting deletes, the objects of its anchors; objects it did not
  create (waypoints, the robot, anything a mission declared) are never deleted;
* it writes perceived facts, and only facts of the grounding's predicates;
* a visible anchor is fresh evidence: its facts become exactly what perception says, so an
  expected fact (an action's predicted effect) perception confirms becomes perceived, and one it
  contradicts is deleted; declared facts are left alone;
* an anchor out of view is stale evidence: only what changed in it is written, so a fact an
  action removed is not put back from an old observation.
"""

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from merlin2_sailor.knowledge.changes import Change, ChangeEvent, Operation, key_of, kind_of
from merlin2_sailor.knowledge.grounding import GroundableAnchor, GroundedAnchor, Grounding
from merlin2_sailor.knowledge.model import PddlObject, Proposition, PropositionKey, Provenance
from merlin2_sailor.knowledge.store import KnowledgeBase


@dataclass(frozen=True)
class SyncPlan:
    """The batch one call will send, and the grounding it brings the store to."""

    changes: tuple[Change, ...]
    grounded: dict[str, GroundedAnchor] = field(repr=False)
    created_objects: frozenset[str] = frozenset()


class KnowledgeSync:
    """Writes the grounding of the current anchors into a store, by diff.

    Not thread-safe: call :meth:`sync` from one thread (the node's knowledge timer).
    """

    def __init__(
        self, store: KnowledgeBase, grounding: Grounding, owned: Iterable[str] = ()
    ) -> None:
        """``owned`` names objects an earlier sync of the same anchors created (saved with the
        anchors, see :attr:`owned_objects`): after a restart they are this sync's again, so an
        anchor forgotten later still takes its object and facts with it."""
        self._store = store
        self._grounding = grounding
        self._managed_predicates = grounding.managed_predicates
        self._declarations = grounding.declarations()
        self._declared_keys = {(kind_of(item), key_of(item)) for item in self._declarations}
        self._declarations_missing = True
        self._grounded: dict[str, GroundedAnchor] = {}
        self._created: set[str] = set()
        # Objects whose creation was sent in a batch that failed: the store may have applied it
        # and lost only the answer (a remote KB killed mid-request), so it may hold them.
        self._unconfirmed: set[str] = set()
        # Objects that existed before the sync created any: reading them once, at start, is
        # the only read the sync makes; afterwards store events keep these sets current.
        self._foreign_objects = {pddl_object.name for pddl_object in store.objects.get_all()}
        # The store's facts of managed predicates about objects this sync grounds, any provenance.
        self._facts: dict[str, dict[PropositionKey, Proposition]] = {}
        self._last_heard: Sequence[ChangeEvent] = ()
        for name in owned:
            self._adopt(name)
        self._unsubscribe = store.subscribe(self._hear)

    @property
    def owned_objects(self) -> frozenset[str]:
        """The objects this sync created and will delete when their anchors go; persist them."""
        return frozenset(self._created)

    @property
    def unconfirmed_objects(self) -> frozenset[str]:
        """Objects this sync tried to create in a batch that failed and has not created since.

        The store may hold them anyway (it applied the batch, the answer was lost). A sync rebuilt
        after the failure must be given them as ``owned``: it adopts those the store holds, where
        it would otherwise take them for someone else's objects and never delete them.
        """
        return frozenset(self._unconfirmed - self._created)

    def _adopt(self, name: str) -> None:
        stored = self._store.objects.get(name)
        if stored is None:
            return
        self._foreign_objects.discard(name)
        self._created.add(name)
        facts = {
            fact.key: fact
            for fact in self._store.propositions_about(name)
            if not fact.is_goal and fact.predicate in self._managed_predicates
        }
        self._facts[name] = facts
        perceived = frozenset(f for f in facts.values() if f.provenance is Provenance.PERCEIVED)
        self._grounded[name] = GroundedAnchor(stored, perceived, visible=False)

    def plan(self, anchors: Iterable[GroundableAnchor]) -> SyncPlan:
        """The changes that would bring the store to these anchors; changes nothing itself."""
        grounded = self._grounding.ground(anchors)
        changes: list[Change] = []
        if self._declarations_missing:
            changes += [Change.save(item) for item in self._declarations]
        for name, synced in self._grounded.items():
            if name not in grounded:
                changes += self._forget(name, synced)
        created: set[str] = set()
        for name, current in grounded.items():
            previous = self._grounded.get(name)
            if previous is None or previous.object != current.object:
                changes.append(Change.save(current.object))
                if name not in self._foreign_objects and name not in self._created:
                    created.add(name)
            if current.visible:
                changes += self._reconcile(current)
            else:
                changes += self._update(previous, current)
        return SyncPlan(tuple(changes), grounded, frozenset(created))

    def sync(self, anchors: Iterable[GroundableAnchor]) -> tuple[ChangeEvent, ...]:
        """Bring the store up to date with one batch; returns what changed in the store.

        On error (the store rejected the batch) the sync keeps its previous view, so the next
        call retries the whole difference.
        """
        return self.apply(self.plan(anchors))

    def apply(self, plan: SyncPlan) -> tuple[ChangeEvent, ...]:
        """Send a batch that :meth:`plan` made, with nothing changed in between; as :meth:`sync`.

        Planning first lets a caller record the objects the batch will create before they exist
        (a crash in between must not leave them in the store with nobody owning them).
        """
        previous_grounded = self._grounded
        # Set before applying, so the events of this very batch are heard as being about ours.
        self._grounded = dict(plan.grounded)
        self._created |= plan.created_objects
        try:
            events = self._store.apply(plan.changes) if plan.changes else ()
        except BaseException:
            self._grounded = previous_grounded
            self._created -= plan.created_objects
            self._unconfirmed |= plan.created_objects
            raise
        self._declarations_missing = False
        for name in previous_grounded.keys() - plan.grounded.keys():
            self._facts.pop(name, None)
        # A local store has already told us, with this very tuple; a remote one may tell us
        # later, and hearing a batch twice is harmless.
        if events is not self._last_heard:
            self._hear(events)
        return events

    def close(self) -> None:
        """Stop listening to the store; the sync cannot be used afterwards."""
        self._unsubscribe()

    # Planning.

    def _forget(self, name: str, previous: GroundedAnchor) -> list[Change]:
        if name in self._created:
            return [Change.delete(previous.object)]  # Its facts go with it.
        return [
            Change.delete(fact)
            for fact in self._facts.get(name, {}).values()
            if fact.provenance is Provenance.PERCEIVED
        ]

    def _reconcile(self, current: GroundedAnchor) -> list[Change]:
        present = self._facts.get(current.object.name, {})
        wanted = {fact.key: fact for fact in current.facts}
        changes = [
            Change.save(fact)
            for key, fact in wanted.items()
            if key not in present or present[key].provenance is Provenance.EXPECTED
        ]
        changes += [
            Change.delete(fact)
            for key, fact in present.items()
            if key not in wanted and fact.provenance is not Provenance.DECLARED
        ]
        return changes

    def _update(self, previous: GroundedAnchor | None, current: GroundedAnchor) -> list[Change]:
        present = self._facts.get(current.object.name, {})
        before = previous.facts if previous is not None else frozenset()
        changes = [
            Change.save(fact) for fact in current.facts - before if present.get(fact.key) != fact
        ]
        changes += [
            Change.delete(fact) for fact in before - current.facts if present.get(fact.key) == fact
        ]
        return changes

    # Listening.

    def _hear(self, events: Sequence[ChangeEvent]) -> None:
        """Track, from the store's events, what the plan needs without reading the store."""
        self._last_heard = events
        for event in events:
            item = event.item
            if isinstance(item, Proposition):
                self._hear_proposition(event.operation, item)
            elif isinstance(item, PddlObject):
                self._hear_object(event.operation, item)
            if (
                event.operation is Operation.DELETE
                and (event.kind, key_of(item)) in self._declared_keys
            ):
                self._declarations_missing = True

    def _hear_proposition(self, operation: Operation, proposition: Proposition) -> None:
        if proposition.is_goal or proposition.predicate not in self._managed_predicates:
            return
        for name in proposition.objects:
            if name in self._grounded:
                facts = self._facts.setdefault(name, {})
                if operation is Operation.SAVE:
                    facts[proposition.key] = proposition
                else:
                    facts.pop(proposition.key, None)

    def _hear_object(self, operation: Operation, pddl_object: PddlObject) -> None:
        name = pddl_object.name
        if operation is Operation.SAVE:
            if name not in self._created:
                self._foreign_objects.add(name)
            return
        self._foreign_objects.discard(name)
        self._created.discard(name)
        self._facts.pop(name, None)
        # Someone deleted an object the sync grounds: forget it was synced, so that, while the
        # anchor lives, the next call recreates it from perception.
        self._grounded.pop(name, None)
