"""The MERLIN2 adapter against stand-ins of MERLIN2's and KANT's documented Python interfaces.

The stand-ins follow what MERLIN2's README and sources document: ``Merlin2Action.__init__(name)``
asks ``create_parameters`` / ``create_conditions`` / ``create_effects`` for KANT DTOs and calls
``save_action()`` with ``self.dao_factory`` set; ``Merlin2FsmAction`` is also a YASMIN
StateMachine whose ``run_action(goal)`` puts the goal on the blackboard under
``"merlin2_action_goal"`` and returns whether the machine succeeded; ``cancel_action`` cancels it.
They are injected into ``sys.modules``, so no MERLIN2 is needed.
"""

from __future__ import annotations

import dataclasses
import sys
import threading
import types
from dataclasses import dataclass

import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, StateMachine

from .fake_robot import FakeRobot, make_robot


class _Dto:
    def __init__(self, name: str) -> None:
        self._name = name

    def get_name(self) -> str:
        return self._name


class PddlTypeDto(_Dto):
    pass


class PddlObjectDto(_Dto):
    def __init__(self, pddl_type: PddlTypeDto, name: str) -> None:
        super().__init__(name)
        self.type = pddl_type


class PddlPredicateDto(_Dto):
    def __init__(self, name: str, types: list[PddlTypeDto]) -> None:
        super().__init__(name)
        self.types = types


class PddlConditionEffectDto:
    AT_START, AT_END, OVER_ALL = "at start", "at end", "over all"

    def __init__(self, predicate: PddlPredicateDto, objects: list[PddlObjectDto] | None = None,
                 time: str | None = None, is_negative: bool = False) -> None:
        self.predicate, self.objects, self.time, self.is_negative = predicate, objects or [], time, is_negative

    def text(self) -> str:
        atom = f"{self.predicate.get_name()}({', '.join(o.get_name() for o in self.objects)})"
        return f"{self.time}: {'not ' if self.is_negative else ''}{atom}"


@dataclass
class Dao:
    saved: list

    def get(self, name: str):  # noqa: ANN201
        return next((dto for dto in self.saved if dto.get_name() == name), None)

    def save(self, dto) -> bool:  # noqa: ANN001
        self.saved.append(dto)
        return True


class DaoFactory:
    def __init__(self) -> None:
        self.saved: list = []

    def create_pddl_type_dao(self) -> Dao:
        return Dao(self.saved)

    def create_pddl_predicate_dao(self) -> Dao:
        return Dao(self.saved)

    def create_pddl_action_dao(self) -> Dao:
        return Dao(self.saved)


class Merlin2Action:
    def __init__(self, a_name: str, durative: bool = True) -> None:
        self.action_name = a_name
        self.duration = 10  # KANT's PddlActionDto default
        self.dao_factory = DaoFactory()
        self.parameters = self.create_parameters()
        self.effects = self.create_effects()
        self.conditions = self.create_conditions()
        if not self.save_action():
            raise RuntimeError(f"Wrong PDDL action: {a_name}")
        self.destroyed = False

    def get_name(self) -> str:
        return self.action_name

    def set_duration(self, duration: int) -> None:
        self.duration = duration

    def save_action(self) -> bool:
        return self.dao_factory.create_pddl_action_dao().save(self)

    def destroy_node(self) -> None:
        self.destroyed = True


class Merlin2FsmAction(Merlin2Action, StateMachine):
    def __init__(self, action_name: str) -> None:
        Merlin2Action.__init__(self, action_name)
        StateMachine.__init__(self, [SUCCEED, ABORT, CANCEL])

    def run_action(self, goal) -> bool:  # noqa: ANN001
        blackboard = Blackboard()
        blackboard["merlin2_action_goal"] = goal
        self.last_blackboard = blackboard
        return self(blackboard) == SUCCEED

    def cancel_action(self) -> None:
        self.cancel_state()


@dataclass
class PlanAction:
    action_name: str
    objects: list[str]


@pytest.fixture
def merlin2(monkeypatch: pytest.MonkeyPatch):  # noqa: ANN201
    fsm_module = types.ModuleType("merlin2_fsm_action")
    fsm_module.Merlin2FsmAction = Merlin2FsmAction
    dto_module = types.ModuleType("kant_dto")
    for dto in (PddlTypeDto, PddlObjectDto, PddlPredicateDto, PddlConditionEffectDto):
        setattr(dto_module, dto.__name__, dto)
    monkeypatch.setitem(sys.modules, "merlin2_fsm_action", fsm_module)
    monkeypatch.setitem(sys.modules, "kant_dto", dto_module)
    from merlin2_sailor_behaviors.merlin2 import load_merlin2, sailor_fsm_action_class

    return sailor_fsm_action_class(load_merlin2())


@pytest.fixture
def robot() -> FakeRobot:
    return make_robot()


def test_without_merlin2_the_adapter_says_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "merlin2_fsm_action", None)
    from merlin2_sailor_behaviors.merlin2 import load_merlin2

    with pytest.raises(DependencyError, match="merlin2_fsm_action.*MERLIN2"):
        load_merlin2()


def test_the_pddl_action_becomes_kant_dtos_saved_after_its_types_and_predicates(merlin2, robot: FakeRobot) -> None:
    node = merlin2(SAILOR_ACTIONS["navigation"], lambda node, stopping: robot.context)
    assert [(p.get_name(), p.type.get_name()) for p in node.parameters] == [("o", "wp"), ("d", "wp")]
    assert [c.text() for c in node.conditions] == ["at start: robot_at(o)"]
    assert [e.text() for e in node.effects] == ["at start: not robot_at(o)", "at end: robot_at(d)"]
    saved = [type(dto).__name__ + ":" + dto.get_name() for dto in node.dao_factory.saved]
    assert saved == ["PddlTypeDto:wp", "PddlPredicateDto:robot_at", "SailorMerlin2FsmAction:navigation"]


def test_each_action_is_registered_with_its_own_duration_in_whole_seconds(merlin2, robot: FakeRobot) -> None:
    action = SAILOR_ACTIONS["navigation"]
    slow = dataclasses.replace(action, pddl=dataclasses.replace(action.pddl, duration=42.5))
    assert merlin2(slow, lambda node, stopping: robot.context).duration == 43


def test_run_action_puts_the_goal_objects_under_the_parameter_names_and_runs_the_machine(
    merlin2, robot: FakeRobot
) -> None:
    node = merlin2(SAILOR_ACTIONS["navigation"], lambda node, stopping: robot.context)
    assert node.run_action(PlanAction("navigation", ["a", "b"]))
    assert node.last_blackboard["d"] == "b"
    assert (robot.navigation.goals[0].x, robot.navigation.goals[0].y) == (2.0, 0.0)
    assert not node.run_action(PlanAction("navigation", ["a"]))  # wrong arity: aborted, not a crash


def test_cancel_action_reaches_the_running_sailor_state(merlin2, robot: FakeRobot) -> None:
    robot.navigation.block = True
    node = merlin2(SAILOR_ACTIONS["navigation"], lambda node, stopping: robot.context)
    results: list[bool] = []
    thread = threading.Thread(target=lambda: results.append(node.run_action(PlanAction("navigation", ["a", "c"]))))
    thread.start()
    assert robot.navigation.started.wait(5.0)
    node.cancel_action()
    thread.join(5.0)
    assert results == [False] and robot.navigation.cancelled.is_set()


def test_every_sailor_action_adapts(merlin2, robot: FakeRobot) -> None:
    for action in SAILOR_ACTIONS.values():
        node = merlin2(action, lambda node, stopping: robot.context)
        assert [p.get_name() for p in node.parameters] == list(action.parameter_names)
        node.destroy_node()
        assert node.destroyed
