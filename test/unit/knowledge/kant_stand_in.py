"""A stand-in for KANT's kant_dto and kant_dao packages, following their documented API.

DTOs: PddlTypeDto(name); PddlObjectDto(type, name); PddlPredicateDto(name, types);
PddlPropositionDto(predicate, objects, is_goal); PddlConditionEffectDto(predicate, objects, time,
is_negative); PddlActionDto(name, parameters, conditions, effects, durative) with set_duration.
DAOs (from a factory's create_pddl_<kind>_dao()): get(name), get_all(), save(dto) -> bool,
delete(dto) -> bool, delete_all() -> bool. Written for these tests; no KANT code.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any


class PddlTypeDto:
    def __init__(self, name: str) -> None:
        self._name = name

    def get_name(self) -> str:
        return self._name


class PddlObjectDto:
    def __init__(self, type: PddlTypeDto, name: str) -> None:  # noqa: A002 - KANT's signature
        self._type, self._name = type, name

    def get_type(self) -> PddlTypeDto:
        return self._type

    def get_name(self) -> str:
        return self._name


class PddlPredicateDto:
    def __init__(self, name: str, types: list[PddlTypeDto] | None = None) -> None:
        self._name, self._types = name, types or []

    def get_name(self) -> str:
        return self._name

    def get_types(self) -> list[PddlTypeDto]:
        return self._types


class PddlPropositionDto:
    def __init__(self, predicate: PddlPredicateDto, objects: list[PddlObjectDto] | None = None,
                 is_goal: bool = False) -> None:
        self._predicate, self._objects, self._is_goal = predicate, objects or [], is_goal

    def get_predicate(self) -> PddlPredicateDto:
        return self._predicate

    def get_objects(self) -> list[PddlObjectDto]:
        return self._objects

    def get_is_goal(self) -> bool:
        return self._is_goal


class PddlConditionEffectDto(PddlPropositionDto):
    def __init__(self, pddl_predicate_dto: PddlPredicateDto, pddl_objects_list: list | None = None,
                 time: str | None = None, is_negative: bool = False) -> None:
        super().__init__(pddl_predicate_dto, pddl_objects_list)
        self._time, self._is_negative = time, is_negative

    def get_time(self) -> str | None:
        return self._time

    def get_is_negative(self) -> bool:
        return self._is_negative


class PddlActionDto:
    def __init__(self, name: str, parameters: list | None = None, conditions: list | None = None,
                 effects: list | None = None, durative: bool = True) -> None:
        self._name, self._parameters = name, parameters or []
        self._conditions, self._effects, self._durative = conditions or [], effects or [], durative
        self._duration: float = 10

    def get_name(self) -> str:
        return self._name

    def get_parameters(self) -> list:
        return self._parameters

    def get_conditions(self) -> list:
        return self._conditions

    def get_effects(self) -> list:
        return self._effects

    def get_durative(self) -> bool:
        return self._durative

    def get_duration(self) -> float:
        return self._duration

    def set_duration(self, duration: float) -> None:
        self._duration = duration


KANT_DTO = SimpleNamespace(
    PddlTypeDto=PddlTypeDto, PddlObjectDto=PddlObjectDto, PddlPredicateDto=PddlPredicateDto,
    PddlPropositionDto=PddlPropositionDto, PddlConditionEffectDto=PddlConditionEffectDto,
    PddlActionDto=PddlActionDto,
)


def proposition_key(dto: PddlPropositionDto) -> tuple:
    return (dto.get_predicate().get_name(), tuple(o.get_name() for o in dto.get_objects()), dto.get_is_goal())


class InMemoryDao:
    """One KANT DAO over a dict; ``refuse`` makes save and delete answer False, as KANT does."""

    def __init__(self, key: Any) -> None:
        self.items: dict[Any, Any] = {}
        self._key = key
        self.refuse = False

    def get(self, name: str) -> Any:
        return self.items.get(name)

    def get_all(self) -> list[Any]:
        return list(self.items.values())

    def save(self, dto: Any) -> bool:
        if self.refuse:
            return False
        self.items[self._key(dto)] = dto
        return True

    def delete(self, dto: Any) -> bool:
        if self.refuse:
            return False
        return self.items.pop(self._key(dto), None) is not None

    def delete_all(self) -> bool:
        self.items.clear()
        return True


class InMemoryDaoFactory:
    def __init__(self) -> None:
        self.types = InMemoryDao(lambda dto: dto.get_name())
        self.objects = InMemoryDao(lambda dto: dto.get_name())
        self.predicates = InMemoryDao(lambda dto: dto.get_name())
        self.propositions = InMemoryDao(proposition_key)
        self.actions = InMemoryDao(lambda dto: dto.get_name())

    def create_pddl_type_dao(self) -> InMemoryDao:
        return self.types

    def create_pddl_object_dao(self) -> InMemoryDao:
        return self.objects

    def create_pddl_predicate_dao(self) -> InMemoryDao:
        return self.predicates

    def create_pddl_proposition_dao(self) -> InMemoryDao:
        return self.propositions

    def create_pddl_action_dao(self) -> InMemoryDao:
        return self.actions
