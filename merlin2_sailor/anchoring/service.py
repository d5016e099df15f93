"""AnchoringService: the whole anchoring layer without ROS, built from its settings in one place.

What the anchoring node runs, and what ``sailor replay``, ``sailor evaluate`` and the benchmarks
run too, so that offline figures are figures of the deployed system:

* the core :class:`~.anchoring.Anchoring`, with the matcher and crop embedder the settings name
  (:mod:`.matcher_registry`);
* the symbol counter, persisted in the state folder before any new symbol can reach anyone, and
  moved past every object the knowledge base has seen from this service after a crash;
* the anchors restored from the state folder;
* the :class:`~.persistence_worker.PersistenceWorker` thread that syncs the knowledge base and
  saves the anchors off the hot path, from frozen copies.

The core is single-threaded. Whoever drives it (one thread) holds :attr:`AnchoringService.lock`
around every call; every other thread reads anchors only through :meth:`AnchoringService.views`,
frozen copies taken under the lock.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from typing import Any

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_view import AnchorView, views_of
from merlin2_sailor.anchoring.anchoring import Anchoring
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.matcher_registry import create_matching
from merlin2_sailor.anchoring.matching_table import Embedder
from merlin2_sailor.anchoring.persistence_worker import AnchorsCopy, Logger, PersistenceWorker
from merlin2_sailor.anchoring.settings import AnchoringSettings, default_settings
from merlin2_sailor.anchoring.state_file import AnchoringStateFile
from merlin2_sailor.anchoring.symbols import SymbolCounter
from merlin2_sailor.knowledge.store import KnowledgeBase

#: Opens the knowledge base a location names, waiting at most a timeout (s) for each call:
#: ``knowledge.stores.open_store`` by default, ``ros.stores.open_store`` in ROS nodes.
KnowledgeBaseOpener = Callable[[str, float], KnowledgeBase]


def _silent(level: str, message: str) -> None:
    """The default log: offline tools report through their results, not log lines."""


def _open_store(location: str, timeout: float) -> KnowledgeBase:
    from merlin2_sailor.knowledge.stores import open_store

    return open_store(location, timeout=timeout)


class AnchoringService:
    """The anchoring layer built from ``settings``; :meth:`start` it, :meth:`close` it when done.

    ``log(level, message)`` receives what people should hear ("info", "warning", "error");
    ``open_knowledge_base(location, timeout)`` opens the store ``settings.persistence.knowledge_base``
    names (the ROS-free stores by default; a node hands in the opener that knows ``ros://``);
    ``matcher`` / ``embedder`` replace the ones the settings name (a test's scripted matcher).
    Usable as a context manager (started on entry, closed on exit).
    """

    def __init__(
        self,
        settings: AnchoringSettings | None = None,
        log: Logger = _silent,
        open_knowledge_base: KnowledgeBaseOpener = _open_store,
        matcher: Matcher | None = None,
        embedder: Embedder | None = None,
    ) -> None:
        self.settings = settings or default_settings()
        self.lock = threading.Lock()
        persistence = self.settings.persistence
        self._state_file = AnchoringStateFile(persistence.state_folder) if persistence.state_folder else None
        saved = self._state_file.load() if self._state_file else None
        self._symbols = SymbolCounter(saved.symbol_indices if saved else None)
        if saved and saved.owned_objects:
            self._symbols.note_used(saved.owned_objects)  # symbols the knowledge base has seen
        if matcher is None:
            matcher, embedder = create_matching(self.settings.matcher, report=lambda message: log("warning", message))
        self.matcher, self.embedder = matcher, embedder
        self.anchoring = Anchoring(self.settings.core, matcher, embedder, symbol_factory=self._new_symbol)
        if saved and saved.snapshot:
            self.anchoring.restore(saved.snapshot)
        #: How many anchors the state folder gave back at start.
        self.restored = len(self.anchoring)
        self._worker: PersistenceWorker | None = None
        location = persistence.knowledge_base
        if self._state_file is not None or location:
            self._worker = PersistenceWorker(
                self.copy_anchors, self._state_file,
                (lambda: open_knowledge_base(location, persistence.knowledge_base_timeout)) if location else None,
                self._grounding() if location else None,
                # Restored anchors are this service's objects in the knowledge base, saved as owned or not.
                owned_objects=(saved.owned_objects if saved else frozenset())
                | {anchor.symbol for anchor in self.anchoring.anchors},
                sync_period=persistence.sync_period, save_period=persistence.save_period, log=log,
            )
        self._started = False

    def describe_inference(self) -> str:
        """What the network and the crop backbone run on, for the node's start-up line ("" for the rules)."""
        if self.embedder is None and not self.matcher.uses_appearance:
            return ""
        threads = max(self.matcher.threads, getattr(self.embedder, "threads", 0))
        measured = f" ({threads} threads in use)" if threads else ""
        return f"{self.settings.matcher.inference.describe()}{measured}"

    def _grounding(self) -> Any:
        from merlin2_sailor.knowledge.grounding import Grounding, GroundingConfig
        from merlin2_sailor.resources import config_path

        return Grounding(GroundingConfig.from_yaml(config_path(self.settings.persistence.grounding, "grounding.yaml")))

    # --- life -------------------------------------------------------------------------------

    def start(self) -> AnchoringService:
        """Start the persistence worker (when there is anything to persist)."""
        if self._worker is not None and not self._started:
            self._worker.start()
        self._started = True
        return self

    def close(self) -> None:
        """Stop the worker: it saves, then syncs one last time. Idempotent."""
        if self._worker is not None and self._started:
            self._worker.stop()
        self._started = False
        self._worker = None

    def __enter__(self) -> AnchoringService:
        return self.start()

    def __exit__(self, *_: object) -> None:
        self.close()

    @property
    def persists(self) -> bool:
        """Whether anything leaves memory (a state folder or a knowledge base)."""
        return self._worker is not None

    # --- reading from any thread ------------------------------------------------------------

    def views(self, selected: Callable[[Anchor], bool] | None = None) -> list[AnchorView]:
        """Frozen copies of the anchors (those ``selected`` keeps), by symbol, taken under the lock."""
        with self.lock:
            anchors = [anchor for anchor in self.anchoring.anchors if selected is None or selected(anchor)]
            return sorted(views_of(anchors), key=lambda view: view.symbol)

    def views_of(self, symbols: Iterable[str]) -> dict[str, AnchorView]:
        """Frozen copies of the named anchors that exist, taken under the lock (no walk over all)."""
        with self.lock:
            found = (self.anchoring.get(symbol) for symbol in set(symbols))
            return {anchor.symbol: AnchorView.of(anchor) for anchor in found if anchor is not None}

    def copy_anchors(self) -> AnchorsCopy:
        """What the persistence worker needs, frozen under the lock; the snapshot only when due."""
        with self.lock:
            views = views_of(self.anchoring.anchors)

        def snapshot() -> dict[str, Any]:
            with self.lock:
                return self.anchoring.snapshot()

        return AnchorsCopy(views, snapshot)

    # --- symbols ----------------------------------------------------------------------------

    @property
    def symbol_indices(self) -> dict[str, int]:
        """The last index handed out per class."""
        return self._symbols.last_indices

    def _new_symbol(self, class_name: str) -> str:
        symbol = self._symbols(class_name)
        if self._state_file is not None:  # before the symbol can reach anyone
            self._state_file.save_symbols(self._symbols.last_indices)
        return symbol
