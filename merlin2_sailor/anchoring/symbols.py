"""Where anchor symbols come from: a factory the caller hands in, with an in-memory default.

A symbol (``cup_3``) is the name the planner knows an object by, so it must never be handed out
twice, not even across a restart: a plan made before the restart may still mention ``cup_3``.
That is why the anchoring core does not count by itself but asks a *symbol factory*. The
anchoring node owns the one counter: a :class:`SymbolCounter` whose indices it saves in its state
folder (``state_file.py``) before a new symbol can reach anyone, and moves past every symbol it
restores or finds in the knowledge base. Without a state folder, a :class:`SymbolCounter` alone
serves tests, benchmarks and offline use.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping

from merlin2_sailor.knowledge.naming import symbol as symbol_name
from merlin2_sailor.knowledge.naming import to_identifier

#: A callable ``class_name -> fresh symbol``, e.g. a :class:`SymbolCounter`.
SymbolFactory = Callable[[str], str]


class SymbolCounter:
    """Per-class counters starting at 1, keyed by the class's PDDL identifier.

    The counters belong to the instance (never to the class), so two anchoring cores in one
    process, or two tests, never share a sequence.
    """

    def __init__(self, last_indices: Mapping[str, int] | None = None) -> None:
        """``last_indices`` resumes counters saved by an earlier run (see :attr:`last_indices`)."""
        self._last_index: dict[str, int] = dict(last_indices or {})

    @property
    def last_indices(self) -> dict[str, int]:
        """The last index handed out per class, to save and resume after a restart."""
        return dict(self._last_index)

    def __call__(self, class_name: str) -> str:
        prefix = to_identifier(class_name)
        index = self._last_index.get(prefix, 0) + 1
        self._last_index[prefix] = index
        return symbol_name(prefix, index)

    def note_used(self, symbols: Iterable[str]) -> None:
        """Move the counters past symbols already in use (after a restore), so none is reissued.

        Symbols that do not end in ``_<number>`` were not made by a counter and cannot collide
        with one, so they are ignored.
        """
        for used in symbols:
            prefix, separator, number = used.rpartition("_")
            if separator and prefix and number.isdigit():
                self._last_index[prefix] = max(self._last_index.get(prefix, 0), int(number))
