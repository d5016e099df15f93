"""The mission runtime used where MERLIN2 is absent: plan over the knowledge base, dispatch, replan.

ROS-free: planning goes through unified-planning (engine by name, Tamer by default), steps run
behaviours written against :mod:`merlin2_sailor_behaviors.state_machines`, and every fact moves
through the :class:`~merlin2_sailor.knowledge.KnowledgeBase` port.
"""

from merlin2_sailor_behaviors.planning.dispatcher import (
    PLAN_STEP_KEY,
    Behaviour,
    Dispatcher,
    DispatcherConfig,
)
from merlin2_sailor_behaviors.planning.effects import (
    AppliedEffects,
    EffectWriter,
    anchored_by_provenance,
)
from merlin2_sailor_behaviors.planning.mission import Mission, MissionRunner
from merlin2_sailor_behaviors.planning.mission_result import MissionResult, MissionStatus
from merlin2_sailor_behaviors.planning.plan import Plan, PlanStep
from merlin2_sailor_behaviors.planning.planner import (
    ENGINE_REQUIREMENTS,
    Planner,
    PlannerConfig,
    PlanningResult,
    PlanningStatus,
)
from merlin2_sailor_behaviors.planning.task import PlanningTask, task_from_store

__all__ = [
    "ENGINE_REQUIREMENTS",
    "PLAN_STEP_KEY",
    "AppliedEffects",
    "Behaviour",
    "Dispatcher",
    "DispatcherConfig",
    "EffectWriter",
    "Mission",
    "MissionResult",
    "MissionRunner",
    "MissionStatus",
    "Plan",
    "PlanStep",
    "Planner",
    "PlannerConfig",
    "PlanningResult",
    "PlanningStatus",
    "PlanningTask",
    "anchored_by_provenance",
    "task_from_store",
]
