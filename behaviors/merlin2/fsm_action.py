"""A SAILOR action as a MERLIN2 FSM action: the same PDDL action and state machine, MERLIN2's way.

MERLIN2's Python action base (``merlin2_action.merlin2_action.Merlin2Action``) is a ROS node and
a KANT ``PddlActionDto`` at once: on construction it asks the subclass for its PDDL parameters,
conditions and effects (``create_parameters``, ``create_conditions``, ``create_effects``, lists
of KANT DTOs), saves the action in MERLIN2's knowledge base through KANT's DAOs
(``save_action``; its DAO factory is ``self.dao_factory``), serves ``run_action(goal)`` /
``cancel_action()`` for MERLIN2's executor and deletes the action in ``destroy_node``.
``merlin2_fsm_action.Merlin2FsmAction`` adds YASMIN's ``StateMachine`` to it: ``run_action``
runs the machine with the plan step (a ``PlanAction``, objects in parameter order) on the
blackboard under ``"merlin2_action_goal"``, and ``cancel_action`` is ``cancel_state``.

:func:`sailor_fsm_action_class` builds, from those classes, one adapter class whose instances
wrap a :class:`~merlin2_sailor_behaviors.actions.SailorAction`:

* its PDDL action becomes KANT DTOs (the root type ``object`` as a type DTO, as the KANT store
  writes it);
* ``save_action`` first declares the types and predicates the action needs, then saves it;
* the machine is ``READING_GOAL`` (copies the goal's objects onto the blackboard under the
  parameter names, plus the plan step, as the dispatcher does) then the SAILOR machine itself,
  built by the action's factory from a context the caller makes from the node
  (:func:`merlin2_sailor_behaviors.merlin2.context.ros_context_factory` for the real robot).

Nothing here imports MERLIN2 until asked: :func:`load_merlin2` imports ``merlin2_fsm_action`` and
``kant_dto`` and raises a DependencyError saying what to install when they are missing.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.knowledge import PddlAction
from merlin2_sailor.knowledge.kant_projection import kant_duration
from merlin2_sailor.knowledge.model import TimedLiteral
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.keys import PLAN_STEP_KEY, REASON_KEY
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.planning.plan import PlanStep
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, CbState

FSM_ACTION_MODULE = "merlin2_fsm_action"
KANT_DTO_MODULE = "kant_dto"
GOAL_KEY = "merlin2_action_goal"
"""Where MERLIN2's FSM action puts the plan step (a merlin2_msgs PlanAction) on the blackboard."""

ContextFactory = Callable[[Any, threading.Event], BehaviorContext]
"""Builds the behaviours' context from the MERLIN2 action node (an rclpy node) and an event that
is set when the node is being destroyed (so blocking calls give up)."""


@dataclass(frozen=True)
class Merlin2Api:
    """The MERLIN2 and KANT classes the adapter is built from."""

    fsm_action: type
    type_dto: type
    object_dto: type
    predicate_dto: type
    condition_effect_dto: type


def load_merlin2() -> Merlin2Api:
    """MERLIN2's FSM action base and KANT's DTOs, imported now.

    Raises:
        DependencyError: MERLIN2 (``merlin2_fsm_action``) or KANT (``kant_dto``) is not importable.
    """
    modules = {}
    for name in (FSM_ACTION_MODULE, KANT_DTO_MODULE):
        try:
            modules[name] = importlib.import_module(name)
        except ImportError as error:
            raise DependencyError(
                f"running SAILOR's behaviours as MERLIN2 actions needs MERLIN2's {name!r} ({error}); "
                "build MERLIN2 and KANT in a ROS 2 workspace (https://github.com/MERLIN2-ARCH/merlin2) "
                "and source it, or serve the behaviours with the 'behaviors' node instead"
            ) from error
    dto = modules[KANT_DTO_MODULE]
    return Merlin2Api(
        fsm_action=modules[FSM_ACTION_MODULE].Merlin2FsmAction,
        type_dto=dto.PddlTypeDto,
        object_dto=dto.PddlObjectDto,
        predicate_dto=dto.PddlPredicateDto,
        condition_effect_dto=dto.PddlConditionEffectDto,
    )


@dataclass(frozen=True)
class ActionDtos:
    """A SAILOR action as KANT DTOs."""

    types: tuple[Any, ...]
    predicates: tuple[Any, ...]
    parameters: tuple[Any, ...]
    conditions: tuple[Any, ...]
    effects: tuple[Any, ...]


def action_dtos(action: SailorAction, api: Merlin2Api) -> ActionDtos:
    """The action's types, predicates, parameters, conditions and effects as KANT DTOs."""
    types = {name: api.type_dto(name) for name in _type_names(action)}
    predicates = {
        predicate.name: api.predicate_dto(predicate.name, [types[t] for t in predicate.parameter_types])
        for predicate in action.predicates
    }
    parameters = {p.name: api.object_dto(types[p.type], p.name) for p in action.pddl.parameters}

    def literal(item: TimedLiteral) -> Any:
        return api.condition_effect_dto(
            predicates[item.predicate],
            [parameters[name] for name in item.arguments],
            time=item.time.value if item.time is not None else None,
            is_negative=item.is_negative,
        )

    pddl: PddlAction = action.pddl
    return ActionDtos(
        types=tuple(types.values()),
        predicates=tuple(predicates.values()),
        parameters=tuple(parameters.values()),
        conditions=tuple(literal(c) for c in pddl.conditions),
        effects=tuple(literal(e) for e in pddl.effects),
    )


def _type_names(action: SailorAction) -> list[str]:
    names = [t.name for t in action.types]
    names += [p.type for p in action.pddl.parameters]
    names += [t for predicate in action.predicates for t in predicate.parameter_types]
    return list(dict.fromkeys(names))


@cache
def sailor_fsm_action_class(api: Merlin2Api | None = None) -> type:
    """The MERLIN2 FSM action class that runs SAILOR actions (built once per API).

    Instantiate it as ``cls(sailor_action, make_context)``; it is a MERLIN2 action node.

    Raises:
        DependencyError: MERLIN2 or KANT is not importable (when ``api`` is not given).
    """
    api = api if api is not None else load_merlin2()

    class SailorMerlin2FsmAction(api.fsm_action):  # type: ignore[misc, valid-type]
        """A SAILOR action registered and run by MERLIN2."""

        def __init__(self, sailor_action: SailorAction, make_context: ContextFactory) -> None:
            self.sailor_action = sailor_action
            self._sailor_dtos = action_dtos(sailor_action, api)
            self._sailor_stopping = threading.Event()
            super().__init__(sailor_action.name)
            machine_name = sailor_action.name.upper()
            # MERLIN2 publishes the machine to YASMIN's viewer on a timer from now on, validating it
            # each time: every state is added with transitions that already lead somewhere.
            self.add_state(
                machine_name,
                sailor_action.make_state_machine(make_context(self, self._sailor_stopping)),
                {SUCCEED: SUCCEED, ABORT: ABORT, CANCEL: CANCEL},
            )
            self.add_state("READING_GOAL", CbState([SUCCEED, ABORT], self._read_goal), {SUCCEED: machine_name})
            self.set_start_state("READING_GOAL")

        # MERLIN2's PDDL hooks.

        def create_parameters(self) -> list[Any]:
            return list(self._sailor_dtos.parameters)

        def create_conditions(self) -> list[Any]:
            return list(self._sailor_dtos.conditions)

        def create_effects(self) -> list[Any]:
            return list(self._sailor_dtos.effects)

        create_efects = create_effects  # the spelling of MERLIN2 releases before 2023

        def save_action(self) -> bool:
            """Declare the types and predicates first, then save the action, with its own duration
            in KANT's whole seconds, as MERLIN2 does."""
            if self.sailor_action.pddl.durative:
                self.set_duration(kant_duration(self.sailor_action.pddl.duration))
            factory = self.dao_factory
            type_dao, predicate_dao = factory.create_pddl_type_dao(), factory.create_pddl_predicate_dao()
            for type_dto in self._sailor_dtos.types:
                if type_dto.get_name() != "object" and type_dao.get(type_dto.get_name()) is None:
                    type_dao.save(type_dto)
            for predicate_dto in self._sailor_dtos.predicates:
                if predicate_dao.get(predicate_dto.get_name()) is None:
                    predicate_dao.save(predicate_dto)
            return super().save_action()

        def destroy_node(self) -> None:
            """Stop a running behaviour's blocking calls, then let MERLIN2 withdraw the action."""
            self._sailor_stopping.set()
            self.cancel_state()
            super().destroy_node()

        # The first state: the plan step onto the blackboard, as SAILOR's behaviours read it.

        def _read_goal(self, blackboard: Blackboard) -> str:
            goal = blackboard[GOAL_KEY]
            objects = tuple(str(name) for name in goal.objects)
            names = self.sailor_action.parameter_names
            if len(objects) != len(names):
                blackboard[REASON_KEY] = (
                    f"{self.sailor_action.name} takes {len(names)} object(s) ({', '.join(names)}), "
                    f"got {list(objects)}"
                )
                return ABORT
            for name, value in zip(names, objects, strict=True):
                blackboard[name] = value
            blackboard[PLAN_STEP_KEY] = PlanStep(self.sailor_action.name, objects)
            return SUCCEED

    return SailorMerlin2FsmAction
