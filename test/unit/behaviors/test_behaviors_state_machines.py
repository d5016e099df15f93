"""The local YASMIN-compatible state machines: transitions, nesting, blackboard, cancellation."""

from __future__ import annotations

import threading

import pytest

from merlin2_sailor.errors import SailorError
from merlin2_sailor_behaviors.state_machines.blackboard import Blackboard
from merlin2_sailor_behaviors.state_machines.errors import StateMachineError
from merlin2_sailor_behaviors.state_machines.outcomes import ABORT, CANCEL, SUCCEED
from merlin2_sailor_behaviors.state_machines.state import CbState, State
from merlin2_sailor_behaviors.state_machines.state_machine import StateMachine

from .waiting_state import WAIT_SECONDS
from .waiting_state import LocalWaitForCancel as WaitForCancel


def record(name: str, outcome: str = SUCCEED) -> CbState:
    """A state that appends its name to the blackboard's ``visited`` list."""

    def callback(blackboard: Blackboard) -> str:
        blackboard.setdefault("visited", []).append(name)
        return outcome

    callback.__name__ = name
    return CbState([SUCCEED, ABORT], callback)


def test_cb_state_returns_its_callbacks_outcome_and_shares_the_blackboard() -> None:
    blackboard = Blackboard({"count": 1})
    state = CbState([SUCCEED], lambda bb: bb.update(count=bb["count"] + 1) or SUCCEED)
    assert state(blackboard) == SUCCEED
    assert blackboard["count"] == 2


def test_state_without_execute_cannot_be_built() -> None:
    with pytest.raises(TypeError):
        State([SUCCEED])  # type: ignore[abstract]


def test_undeclared_outcome_is_a_clear_error() -> None:
    state = CbState([SUCCEED], lambda blackboard: "exploded")
    with pytest.raises(StateMachineError, match=r"'exploded'.*does not declare"):
        state()
    assert issubclass(StateMachineError, SailorError)


def test_undeclared_outcome_inside_a_machine_is_raised_not_swallowed() -> None:
    machine = StateMachine([SUCCEED])
    machine.add_state("boom", CbState([SUCCEED], lambda blackboard: "exploded"))
    with pytest.raises(StateMachineError, match="exploded"):
        machine()


@pytest.mark.parametrize("outcomes", [[], "succeeded", [SUCCEED, SUCCEED], [""]])
def test_bad_outcome_declarations_are_rejected(outcomes: object) -> None:
    with pytest.raises(StateMachineError):
        CbState(outcomes, lambda blackboard: SUCCEED)  # type: ignore[arg-type]


def test_machine_follows_transitions_from_the_first_state() -> None:
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record("first"), transitions={SUCCEED: "second"})
    machine.add_state("second", record("second", ABORT), transitions={ABORT: "third"})
    machine.add_state("third", record("third"), transitions={SUCCEED: SUCCEED})
    blackboard = Blackboard()
    assert machine(blackboard) == SUCCEED
    assert blackboard["visited"] == ["first", "second", "third"]


def test_an_outcome_of_the_machine_needs_no_transition() -> None:
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("only", record("only", ABORT))
    assert machine() == ABORT


def test_transition_can_rename_an_outcome_into_a_machine_outcome() -> None:
    machine = StateMachine(["done"])
    machine.add_state("only", record("only"), transitions={SUCCEED: "done", ABORT: "done"})
    assert machine() == "done"


def test_set_start_state_chooses_where_runs_begin() -> None:
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record("first"))
    machine.add_state("second", record("second"))
    machine.set_start_state("second")
    blackboard = Blackboard()
    machine(blackboard)
    assert blackboard["visited"] == ["second"]


def test_nested_machine_runs_as_a_state_and_shares_the_blackboard() -> None:
    inner = StateMachine([SUCCEED, ABORT])
    inner.add_state("inner_a", record("inner_a"), transitions={SUCCEED: "inner_b"})
    inner.add_state("inner_b", record("inner_b"))
    outer = StateMachine([SUCCEED, ABORT])
    outer.add_state("before", record("before"), transitions={SUCCEED: "nested"})
    outer.add_state("nested", inner, transitions={SUCCEED: "after"})
    outer.add_state("after", record("after"))
    blackboard = Blackboard()
    assert outer(blackboard) == SUCCEED
    assert blackboard["visited"] == ["before", "inner_a", "inner_b", "after"]


def test_every_run_without_a_blackboard_gets_a_fresh_one() -> None:
    seen: list[Blackboard] = []

    def remember(blackboard: Blackboard) -> str:
        assert "mark" not in blackboard  # nothing leaks from an earlier run or another machine
        blackboard["mark"] = True
        seen.append(blackboard)
        return SUCCEED

    machine = StateMachine([SUCCEED])
    machine.add_state("remember", CbState([SUCCEED], remember))
    other = StateMachine([SUCCEED])
    other.add_state("remember", CbState([SUCCEED], remember))
    machine(), machine(), other()
    assert len({id(blackboard) for blackboard in seen}) == 3


def test_blackboard_is_a_mutable_mapping_with_a_helpful_key_error() -> None:
    blackboard = Blackboard({"a": 1})
    blackboard["b"] = 2
    del blackboard["a"]
    assert dict(blackboard) == {"b": 2} and len(blackboard) == 1 and "b" in blackboard
    with pytest.raises(KeyError, match=r"holds \['b'\]"):
        blackboard["a"]


def test_canceled_is_always_an_outcome_of_a_machine() -> None:
    assert CANCEL in StateMachine([SUCCEED]).get_outcomes()


def test_validation_reports_an_unknown_target() -> None:
    machine = StateMachine([SUCCEED])
    machine.add_state("first", record("first"), transitions={SUCCEED: "nowhere", ABORT: SUCCEED})
    with pytest.raises(StateMachineError, match=r"'nowhere', which is neither a state"):
        machine.validate()
    with pytest.raises(StateMachineError, match="nowhere"):
        machine()  # also on the first run


def test_validation_reports_an_unhandled_outcome() -> None:
    machine = StateMachine([SUCCEED])
    machine.add_state("first", record("first"))  # ABORT is neither mapped nor a machine outcome
    with pytest.raises(StateMachineError, match=r"outcome 'aborted' of state 'first'"):
        machine.validate()


def test_validation_reports_an_empty_machine_and_a_missing_start_state() -> None:
    with pytest.raises(StateMachineError, match="no states"):
        StateMachine([SUCCEED]).validate()
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record("first"))
    machine.set_start_state("missing")
    with pytest.raises(StateMachineError, match="start state 'missing'"):
        machine.validate()


def test_validation_descends_into_nested_machines() -> None:
    inner = StateMachine([SUCCEED])
    inner.add_state("broken", record("broken"), transitions={SUCCEED: "nowhere", ABORT: SUCCEED})
    outer = StateMachine([SUCCEED])
    outer.add_state("nested", inner)
    with pytest.raises(StateMachineError, match="in state 'nested'.*nowhere"):
        outer.validate()


def test_add_state_rejects_mistakes_immediately() -> None:
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record("first"))
    with pytest.raises(StateMachineError, match="already has a state"):
        machine.add_state("first", record("again"))
    with pytest.raises(StateMachineError, match="also an outcome"):
        machine.add_state(SUCCEED, record("clash"))
    with pytest.raises(StateMachineError, match=r"\['not_an_outcome'\].*does\s+not declare"):
        machine.add_state("second", record("second"), transitions={"not_an_outcome": SUCCEED})
    with pytest.raises(StateMachineError, match="must be a State"):
        machine.add_state("third", lambda blackboard: SUCCEED)  # type: ignore[arg-type]


def test_cancel_reaches_a_nested_state_running_in_another_thread() -> None:
    waiting = WaitForCancel()
    inner = StateMachine([SUCCEED])
    inner.add_state("wait", waiting)
    after_inner = record("after_inner")
    outer = StateMachine([SUCCEED, ABORT])
    outer.add_state("nested", inner, transitions={SUCCEED: "after"})
    outer.add_state("after", after_inner)
    blackboard = Blackboard()
    result: list[str] = []
    runner = threading.Thread(target=lambda: result.append(outer(blackboard)))
    runner.start()
    assert waiting.started.wait(WAIT_SECONDS)
    assert outer.get_current_state() == "nested" and inner.get_current_state() == "wait"
    outer.cancel_state()
    runner.join(WAIT_SECONDS)
    assert not runner.is_alive()
    assert result == [CANCEL]
    assert waiting.is_canceled() and inner.is_canceled()
    assert "visited" not in blackboard  # the machine stopped; "after" never ran
    assert outer.get_current_state() is None


def test_cancel_ends_the_machine_even_if_the_state_ignores_it() -> None:
    machine = StateMachine([SUCCEED, ABORT])

    def cancel_own_machine(blackboard: Blackboard) -> str:
        machine.cancel_state()  # as if from another thread while this state runs
        return SUCCEED

    machine.add_state("stubborn", CbState([SUCCEED], cancel_own_machine), {SUCCEED: "next"})
    machine.add_state("next", record("next"))
    blackboard = Blackboard()
    assert machine(blackboard) == CANCEL
    assert "visited" not in blackboard


def test_a_machine_can_run_again_after_being_cancelled() -> None:
    waiting = WaitForCancel()
    machine = StateMachine([SUCCEED])
    machine.add_state("wait", waiting)
    result: list[str] = []
    runner = threading.Thread(target=lambda: result.append(machine()))
    runner.start()
    assert waiting.started.wait(WAIT_SECONDS)
    machine.cancel_state()
    runner.join(WAIT_SECONDS)
    assert result == [CANCEL]
    # A cancellation belongs to the run it interrupted: the next run starts clean.
    quick = StateMachine([SUCCEED, ABORT])
    quick.add_state("only", record("only"))
    quick.cancel_state()
    assert quick() == SUCCEED
    assert not quick.is_canceled()


def test_a_child_cancelled_alone_ends_its_parent_through_the_cancel_outcome() -> None:
    inner = StateMachine([SUCCEED])
    inner.add_state("cancel_self", CbState([SUCCEED], lambda bb: inner.cancel_state() or SUCCEED))
    outer = StateMachine([SUCCEED])
    outer.add_state("nested", inner)  # inner's "canceled" is an outcome of outer: no transition
    assert outer() == CANCEL
