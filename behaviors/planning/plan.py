"""A plan as the dispatcher sees it: actions to run in order, each with its objects.

Planners return richer objects (timed plans, parameter expressions); converting them to these
plain dataclasses at the planner's edge keeps the dispatcher, the behaviours and the tests free
of any planning library.
"""

from dataclasses import dataclass


@dataclass(frozen=True)
class PlanStep:
    """One action of a plan with the names of the objects bound to its parameters, in order."""

    action: str
    objects: tuple[str, ...] = ()
    start: float = 0.0
    """When the planner scheduled the action, in plan time (0 for sequential plans)."""
    duration: float | None = None
    """The planned duration of a durative action, None for an instantaneous one."""

    def __str__(self) -> str:
        return f"{self.action}({', '.join(self.objects)})"


@dataclass(frozen=True)
class Plan:
    """Steps in the order the dispatcher runs them (by planned start time)."""

    steps: tuple[PlanStep, ...] = ()

    def __len__(self) -> int:
        return len(self.steps)

    def __str__(self) -> str:
        return " -> ".join(str(step) for step in self.steps) or "(empty plan)"
