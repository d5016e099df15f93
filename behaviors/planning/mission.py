"""A mission in the spirit of MERLIN2's mission node: it declares goals, and the runtime pursues them.

Unlike the examples that start MERLIN2 missions by emptying the knowledge base, a mission here
only adds its goals (as goal propositions, so other MERLIN2 tools see them) and removes, when it
ends, the goals it added. It never deletes objects or facts: the anchors perception put in the
knowledge base are the world the mission plans over.
"""

from collections.abc import Iterable
from dataclasses import dataclass, replace

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import Change, KnowledgeBase, Proposition, Provenance
from merlin2_sailor_behaviors.planning.dispatcher import Dispatcher
from merlin2_sailor_behaviors.planning.mission_result import MissionResult


@dataclass(frozen=True)
class Mission:
    """A named set of goals: facts the robot must make true."""

    goals: tuple[Proposition, ...]
    name: str = "mission"

    def __post_init__(self) -> None:
        goals = tuple(self.goals)
        if not goals:
            raise ConfigurationError(f"mission {self.name!r} declares no goal")
        normalized = tuple(
            replace(goal, is_goal=True, provenance=Provenance.DECLARED) for goal in goals
        )
        object.__setattr__(self, "goals", normalized)


class MissionRunner:
    """Declares a mission's goals in the knowledge base and runs it with a dispatcher."""

    def __init__(self, store: KnowledgeBase, dispatcher: Dispatcher) -> None:
        self._store = store
        self._dispatcher = dispatcher

    def run(self, mission: Mission) -> MissionResult:
        """Run the mission to its end; its goals leave the knowledge base with it."""
        added = self._declare(mission.goals)
        try:
            return self._dispatcher.run(mission.goals)
        finally:
            self._withdraw(added)

    def cancel(self) -> None:
        """Cancel the mission in progress (from any thread)."""
        self._dispatcher.cancel()

    def _declare(self, goals: Iterable[Proposition]) -> list[Proposition]:
        new = [goal for goal in goals if self._store.propositions.get(goal.key) is None]
        if new:
            self._store.apply([Change.save(goal) for goal in new])
        return new

    def _withdraw(self, goals: list[Proposition]) -> None:
        present = [goal for goal in goals if self._store.propositions.get(goal.key) is not None]
        if present:
            self._store.apply([Change.delete(goal) for goal in present])
