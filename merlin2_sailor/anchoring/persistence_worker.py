"""PersistenceWorker: keep the knowledge base and the state file up to date, off the hot path.

The anchoring node must answer every camera frame quickly, while writing the knowledge base
(a service round trip, perhaps to a knowledge base that is down) and saving anchors to disk can
take long. So a thread of its own does both, on its own periods, from frozen copies of the
anchors that the node hands it:

* every ``sync_period`` it brings the knowledge base up to date by diff (KnowledgeSync);
* every ``save_period`` it saves the anchors' snapshot and the objects the sync owns.

A knowledge base that fails is logged and retried; the sync is then rebuilt from what the store
really holds, so a knowledge base that restarted empty is filled again and one that kept its
data gets no duplicates. Anchors are never lost to a knowledge-base failure.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from merlin2_sailor.anchoring.anchor_view import AnchorView
from merlin2_sailor.anchoring.state_file import AnchoringStateFile
from merlin2_sailor.errors import SailorError
from merlin2_sailor.knowledge.grounding import Grounding
from merlin2_sailor.knowledge.store import KnowledgeBase
from merlin2_sailor.knowledge.sync import KnowledgeSync

Logger = Callable[[str, str], None]  # (level: "info" | "warning" | "error", message)


@dataclass(frozen=True)
class AnchorsCopy:
    """What the worker needs of the anchors at one instant, taken under the node's lock."""

    views: Sequence[AnchorView]
    snapshot: Callable[[], dict[str, Any]]  # called only when a save is due


class PersistenceWorker:
    def __init__(
        self,
        copy_anchors: Callable[[], AnchorsCopy],
        state_file: AnchoringStateFile | None,
        open_knowledge_base: Callable[[], KnowledgeBase] | None,
        grounding: Grounding | None,
        owned_objects: frozenset[str] = frozenset(),
        sync_period: float = 0.5,
        save_period: float = 2.0,
        log: Logger = lambda level, message: None,
    ) -> None:
        self._copy_anchors = copy_anchors
        self._state_file = state_file
        self._open_knowledge_base = open_knowledge_base
        self._grounding = grounding
        self._owned = owned_objects
        # Objects a failed batch tried to create: the knowledge base may hold them (see
        # KnowledgeSync.unconfirmed_objects); the rebuilt sync adopts those it finds.
        self._unconfirmed: frozenset[str] = frozenset()
        self._sync_period, self._save_period = sync_period, save_period
        self._log = log
        self._store: KnowledgeBase | None = None
        self._sync: KnowledgeSync | None = None
        self._knowledge_base_ok: bool | None = None
        self._next_save = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="anchoring-persistence", daemon=True)

    @property
    def owned_objects(self) -> frozenset[str]:
        return self._owned

    @property
    def _claimed(self) -> frozenset[str]:
        """What a restarted or rebuilt sync is given as its own: the owned objects and the
        unconfirmed ones (it adopts only those the store holds)."""
        return self._owned | self._unconfirmed

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread; save, then sync one last time (the save first: it matters more)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=30.0)
        anchors = self._copy_anchors()
        self._save(anchors)
        self._guarded(lambda: self._sync_knowledge_base(anchors))
        if self._sync is not None:
            self._sync.close()
        if self._store is not None:
            self._store.close()

    def step(self, force_save: bool = False) -> None:
        """One round: sync the knowledge base, and save the state file when due."""
        anchors = self._copy_anchors()
        self._sync_knowledge_base(anchors)
        if force_save or time.monotonic() >= self._next_save:
            self._save(anchors)

    def _save(self, anchors: AnchorsCopy) -> None:
        if self._state_file is None:
            return
        self._next_save = time.monotonic() + self._save_period
        try:
            self._state_file.save_anchors(anchors.snapshot(), self._claimed)
        except OSError as error:
            self._log("error", f"cannot save anchors to {self._state_file.folder}: {error}")

    def _run(self) -> None:
        while not self._stop.wait(self._sync_period):
            self._guarded(self.step)

    def _guarded(self, work: Callable[[], None]) -> None:
        """Run ``work``; an unexpected error is logged, because this thread must outlive it."""
        try:
            work()
        except Exception as error:  # noqa: BLE001 - the worker keeps the anchors safe; it must not die
            self._log("error", f"anchoring persistence step failed, retrying: {error!r}")

    def _sync_knowledge_base(self, anchors: AnchorsCopy) -> None:
        """Bring the knowledge base to ``anchors``.

        Write-ahead: a batch that will create objects is sent only after the state file holds
        these anchors and claims those objects. A crash after the store applied the batch (even
        before its answer arrived) then restarts with anchors that own the objects, where it once
        left them in the knowledge base for good while the restarted node anchored the same things
        again under new symbols. A claimed object the store never got is simply not adopted.
        """
        if self._open_knowledge_base is None or self._grounding is None:
            return
        try:
            if self._store is None:
                self._store = self._open_knowledge_base()
            if self._sync is None:
                self._sync = KnowledgeSync(self._store, self._grounding, owned=self._claimed)
            plan = self._sync.plan(anchors.views)
            if not plan.created_objects <= self._claimed:
                self._unconfirmed |= plan.created_objects
                self._save(anchors)
            self._sync.apply(plan)
            self._owned = self._sync.owned_objects
            self._unconfirmed = frozenset()
        except SailorError as error:
            if self._knowledge_base_ok is not False:
                self._log("error", f"knowledge base not updated, retrying every "
                                   f"{self._sync_period:g} s; anchors are kept: {error}")
            self._knowledge_base_ok = False
            if self._sync is not None:
                self._unconfirmed |= self._sync.unconfirmed_objects
                self._sync.close()
            self._sync = None  # rebuilt from what the store really holds once it answers
            return
        if self._knowledge_base_ok is False:
            self._log("info", "knowledge base reachable again; it is up to date")
        self._knowledge_base_ok = True
