"""Planning through unified-planning, with the engine named in configuration.

Engines are plug-ins chosen by name, as unified-planning intends. The default is Aries
(``up-aries``, MIT): installable from PyPI with its solver binary inside, it plans with durative
actions directly (MERLIN2's navigation is durative, so no compilation to instantaneous actions is
needed). It searches without end on an unsolvable problem, so it runs under a timeout and a
mission with an unreachable goal fails after it with a clear reason. Tamer (``up-tamer``) proves
small problems unsolvable at once, but its binding's licence allows educational use only.

unified-planning is imported only when a plan is asked for, and each :class:`Planner` has its
own unified-planning ``Environment``, so two planners (or tests) share no hidden state.
"""

from dataclasses import dataclass
from enum import Enum
from typing import Any

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor_behaviors.planning.plan import Plan, PlanStep
from merlin2_sailor_behaviors.planning.task import PlanningTask

ENGINE_REQUIREMENTS = {
    "tamer": "up-tamer==1.1.6",
    "aries": "up-aries==0.5.0",
    "pyperplan": "up-pyperplan==1.1.0",
    "fast-downward": "up-fast-downward==1.0.0",
}
"""What to install for each engine the runtime has been tried with."""


class PlanningStatus(Enum):
    """How a planning call ended, as far as a mission cares."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    """The engine proved, or gave up showing, that no plan reaches the goals."""
    FAILED = "failed"
    """A timeout, memory limit or engine error: no answer either way."""


@dataclass(frozen=True)
class PlannerConfig:
    """Which engine to plan with, and for how long at most (None: the engine's own limit).

    Aries is the default: it plans with durative actions and is MIT-licensed. Tamer also works,
    but its pytamer binding is "free for educational use" only, which an Apache-2.0 robot stack
    cannot depend on. Aries searches without end on an unsolvable problem, hence the timeout.
    """

    engine: str = "aries"
    timeout_seconds: float | None = 10.0

    def __post_init__(self) -> None:
        if not self.engine:
            raise ConfigurationError("planner engine must be named, e.g. 'aries'")
        if self.timeout_seconds is not None and not self.timeout_seconds > 0:
            raise ConfigurationError(
                f"planner timeout must be positive or None, got {self.timeout_seconds!r}"
            )


@dataclass(frozen=True)
class PlanningResult:
    """A plan when one was found, else None and the reason, in words."""

    status: PlanningStatus
    plan: Plan | None = None
    reason: str = ""


class Planner:
    """Turns a :class:`PlanningTask` into a :class:`Plan` with one unified-planning engine."""

    def __init__(self, config: PlannerConfig | None = None) -> None:
        self.config = config or PlannerConfig()
        self._environment: Any = None

    def plan(self, task: PlanningTask) -> PlanningResult:
        """Plan for ``task``; a goal that cannot be reached is a result, not an exception.

        Raises:
            DependencyError: unified-planning or the engine is not installed.
            ConfigurationError: the engine cannot handle this kind of problem.
        """
        environment = self._get_environment()
        from unified_planning.engines import PlanGenerationResultStatus as Status
        from unified_planning.io import PDDLReader

        try:
            problem = PDDLReader(environment=environment).parse_problem_string(
                task.domain, task.problem
            )
        except Exception as error:  # noqa: BLE001 - the text comes from live data; say what broke
            # The problem is written from the knowledge base as it is now; a fact or goal naming
            # something a concurrent change removed is refused by the reader. That is a failed
            # plan with its reason (the mission may plan again), never a crash of the mission.
            return PlanningResult(
                PlanningStatus.FAILED,
                reason=f"the planning problem could not be read: {type(error).__name__}: {error}",
            )
        with environment.factory.OneshotPlanner(name=self.config.engine) as engine:
            if not engine.supports(problem.kind):
                raise ConfigurationError(
                    f"planning engine {self.config.engine!r} cannot solve this problem "
                    f"({problem.kind}); choose an engine that supports it, such as 'aries'"
                )
            if self.config.timeout_seconds is None:
                answer = engine.solve(problem)
            else:
                answer = engine.solve(problem, timeout=self.config.timeout_seconds)
        if answer.status in (Status.SOLVED_SATISFICING, Status.SOLVED_OPTIMALLY):
            return PlanningResult(PlanningStatus.SOLVED, _to_plan(answer.plan))
        if answer.status in (Status.UNSOLVABLE_PROVEN, Status.UNSOLVABLE_INCOMPLETELY):
            return PlanningResult(
                PlanningStatus.UNSOLVABLE,
                reason=f"{self.config.engine} found no plan ({answer.status.name.lower()})",
            )
        return PlanningResult(
            PlanningStatus.FAILED,
            reason=f"{self.config.engine} gave no answer ({answer.status.name.lower()})",
        )

    def _get_environment(self) -> Any:
        if self._environment is None:
            try:
                from unified_planning.environment import Environment
            except ModuleNotFoundError as error:
                raise DependencyError(
                    f"planning needs unified-planning ({error}); install the project's "
                    "requirements.txt"
                ) from error
            environment = Environment()
            environment.credits_stream = None
            if self.config.engine not in environment.factory.engines:
                requirement = ENGINE_REQUIREMENTS.get(self.config.engine, "its up-* package")
                raise DependencyError(
                    f"planning engine {self.config.engine!r} is not installed; "
                    f"pip install {requirement}"
                )
            self._environment = environment
        return self._environment


def _to_plan(up_plan: Any) -> Plan:
    """A unified-planning sequential or time-triggered plan as steps ordered by start time."""
    if hasattr(up_plan, "timed_actions"):
        timed = [
            (float(start), instance, None if duration is None else float(duration))
            for start, instance, duration in up_plan.timed_actions
        ]
    else:
        timed = [(0.0, instance, None) for instance in up_plan.actions]
    timed.sort(key=lambda item: item[0])  # stable: sequential plans keep their order
    return Plan(
        tuple(
            PlanStep(
                action=instance.action.name,
                objects=tuple(
                    parameter.object().name for parameter in instance.actual_parameters
                ),
                start=start,
                duration=duration,
            )
            for start, instance, duration in timed
        )
    )
