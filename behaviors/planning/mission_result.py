"""How a mission ended, with the reason in words for the operator."""

from dataclasses import dataclass
from enum import Enum

from merlin2_sailor_behaviors.planning.plan import Plan, PlanStep


class MissionStatus(Enum):
    """The three ways a mission ends, mirroring an action's outcomes."""

    SUCCEEDED = "succeeded"
    FAILED = "failed"
    CANCELED = "canceled"


@dataclass(frozen=True)
class MissionResult:
    """The end of a mission: status, why, what ran and which plans were made."""

    status: MissionStatus
    reason: str
    executed: tuple[PlanStep, ...] = ()
    plans: tuple[Plan, ...] = ()

    @property
    def replans(self) -> int:
        """How many plans were made after the first."""
        return max(len(self.plans) - 1, 0)

    @property
    def succeeded(self) -> bool:
        """Whether every goal held when the mission ended."""
        return self.status is MissionStatus.SUCCEEDED
