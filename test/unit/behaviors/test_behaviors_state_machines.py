"""The state machines behave as YASMIN 3.2's do: one suite, run on the project's own implementation
and, with SAILOR_UPSTREAM, on the real YASMIN 3.2.0 (so the two cannot drift apart unnoticed).

Errors are checked by YASMIN's built-in types (KeyError, ValueError, RuntimeError); what only the
local implementation promises (one error listing every problem, the StateMachineError family) is
tested at the end, on it alone.
"""

from __future__ import annotations

import threading
import time
from types import SimpleNamespace

import pytest

from merlin2_sailor.errors import SailorError
from merlin2_sailor_behaviors.state_machines import blackboard as local_blackboard
from merlin2_sailor_behaviors.state_machines import state as local_state
from merlin2_sailor_behaviors.state_machines import state_machine as local_state_machine
from merlin2_sailor_behaviors.state_machines.errors import StateMachineError
from merlin2_sailor_behaviors.state_machines.outcomes import ABORT, CANCEL, SUCCEED

WAIT_SECONDS = 5.0


def _local_api() -> SimpleNamespace:
    return SimpleNamespace(State=local_state.State, CbState=local_state.CbState,
                           StateMachine=local_state_machine.StateMachine, Blackboard=local_blackboard.Blackboard)


@pytest.fixture(params=["local", "yasmin"])
def yasmin(request: pytest.FixtureRequest, upstream_stack) -> SimpleNamespace:
    """The classes of one implementation of YASMIN 3.2's Python API."""
    if request.param == "local":
        return _local_api()
    upstream_stack("yasmin")
    import yasmin

    return SimpleNamespace(State=yasmin.State, CbState=yasmin.CbState, StateMachine=yasmin.StateMachine,
                           Blackboard=yasmin.Blackboard)


def record(api: SimpleNamespace, name: str, outcome: str = SUCCEED):
    """A state that appends its name to the blackboard's ``visited`` list."""

    def cb(blackboard) -> str:
        visited = blackboard["visited"] if "visited" in blackboard else []
        blackboard["visited"] = [*visited, name]
        return outcome

    return api.CbState([SUCCEED, ABORT], cb)


def waiting_state(api: SimpleNamespace):
    """A state that runs until cancelled, then returns ``canceled``, telling the test it started."""

    class WaitForCancel(api.State):
        def __init__(self) -> None:
            super().__init__([SUCCEED, CANCEL])
            self.started = threading.Event()

        def execute(self, blackboard) -> str:
            self.started.set()
            deadline = time.monotonic() + WAIT_SECONDS
            while not self.is_canceled() and time.monotonic() < deadline:
                time.sleep(0.002)
            return CANCEL if self.is_canceled() else SUCCEED

    return WaitForCancel()


def run_in_thread(machine, blackboard) -> tuple[threading.Thread, list]:
    result: list = []

    def run() -> None:
        try:
            result.append(machine(blackboard))
        except Exception as error:  # handed to the test
            result.append(error)

    thread = threading.Thread(target=run)
    thread.start()
    return thread, result


# --- Running -------------------------------------------------------------------------------


def test_a_cb_state_runs_its_cb_on_the_shared_blackboard(yasmin) -> None:
    blackboard = yasmin.Blackboard({"count": 1})

    def increment(bb) -> str:
        bb["count"] = bb["count"] + 1
        return SUCCEED

    assert yasmin.CbState([SUCCEED], cb=increment)(blackboard) == SUCCEED
    assert blackboard["count"] == 2


def test_transitions_run_from_the_first_state_to_an_outcome_of_the_machine(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record(yasmin, "first"), transitions={SUCCEED: "second"})
    machine.add_state("second", record(yasmin, "second", ABORT), transitions={ABORT: "third"})
    machine.add_state("third", record(yasmin, "third"), transitions={SUCCEED: SUCCEED})
    blackboard = yasmin.Blackboard()
    assert machine(blackboard) == SUCCEED
    assert blackboard["visited"] == ["first", "second", "third"]


def test_an_outcome_of_the_machine_needs_no_transition_and_a_transition_can_rename_one(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("only", record(yasmin, "only", ABORT))
    assert machine() == ABORT
    renaming = yasmin.StateMachine(["done"])
    renaming.add_state("only", record(yasmin, "only"), transitions={SUCCEED: "done", ABORT: "done"})
    assert renaming() == "done"


def test_a_machine_has_exactly_the_outcomes_it_declares(yasmin) -> None:
    assert set(yasmin.StateMachine([SUCCEED, ABORT]).get_outcomes()) == {SUCCEED, ABORT}


def test_set_start_state_chooses_where_runs_begin(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record(yasmin, "first"))
    machine.add_state("second", record(yasmin, "second"))
    machine.set_start_state("second")
    blackboard = yasmin.Blackboard()
    machine(blackboard)
    assert blackboard["visited"] == ["second"] and machine.get_start_state() == "second"


def test_a_nested_machine_runs_as_a_state_on_the_same_blackboard(yasmin) -> None:
    inner = yasmin.StateMachine([SUCCEED, ABORT])
    inner.add_state("inner_a", record(yasmin, "inner_a"), transitions={SUCCEED: "inner_b"})
    inner.add_state("inner_b", record(yasmin, "inner_b"))
    outer = yasmin.StateMachine([SUCCEED, ABORT])
    outer.add_state("before", record(yasmin, "before"), transitions={SUCCEED: "nested"})
    outer.add_state("nested", inner, transitions={SUCCEED: "after"})
    outer.add_state("after", record(yasmin, "after"))
    blackboard = yasmin.Blackboard()
    assert outer(blackboard) == SUCCEED
    assert blackboard["visited"] == ["before", "inner_a", "inner_b", "after"]


def test_the_current_state_while_running_and_empty_between_runs(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED])
    seen = []
    machine.add_state("look", yasmin.CbState([SUCCEED], lambda bb: seen.append(machine.get_current_state()) or SUCCEED))
    assert machine.get_current_state() == ""
    machine()
    assert seen == ["look"] and machine.get_current_state() == ""


def test_a_state_is_running_only_while_it_executes(yasmin) -> None:
    seen = []

    class Probe(yasmin.State):
        def __init__(self) -> None:
            super().__init__([SUCCEED])

        def execute(self, blackboard) -> str:
            seen.append(self.is_running())
            return SUCCEED

    probe = Probe()
    probe()
    assert seen == [True] and not probe.is_running()


def test_remappings_let_a_state_read_other_keys(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED])
    read = []
    machine.add_state("read", yasmin.CbState([SUCCEED], lambda bb: read.append(bb["goal"]) or SUCCEED),
                      transitions={SUCCEED: "plain"}, remappings={"goal": "kitchen_goal"})
    machine.add_state("plain", yasmin.CbState([SUCCEED], lambda bb: read.append("goal" in bb) or SUCCEED))
    machine(yasmin.Blackboard({"kitchen_goal": "cup_1"}))
    assert read == ["cup_1", False]


def test_start_transition_and_end_callbacks_with_their_arguments(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record(yasmin, "first"), transitions={SUCCEED: "second"})
    machine.add_state("second", record(yasmin, "second"))
    calls = []
    machine.add_start_cb(lambda bb, start, tag: calls.append(("start", start, tag)), ["x"])
    machine.add_transition_cb(lambda bb, source, target, outcome: calls.append(("move", source, target, outcome)))
    machine.add_end_cb(lambda bb, outcome: calls.append(("end", outcome)))
    machine.add_end_cb(lambda bb, outcome: 1 / 0)  # a failing callback is logged, not fatal
    assert machine() == SUCCEED
    assert calls == [("start", "first", "x"), ("move", "first", "second", SUCCEED), ("end", SUCCEED)]


def test_every_run_without_a_blackboard_gets_a_fresh_one(yasmin) -> None:
    seen = []

    def remember(blackboard) -> str:
        assert "mark" not in blackboard
        blackboard["mark"] = True
        seen.append(blackboard)
        return SUCCEED

    machine = yasmin.StateMachine([SUCCEED])
    machine.add_state("remember", yasmin.CbState([SUCCEED], remember))
    machine(), machine()
    assert len({id(blackboard) for blackboard in seen}) == 2


def test_the_blackboard_offers_item_access_membership_deletion_and_length(yasmin) -> None:
    blackboard = yasmin.Blackboard({"a": 1})
    blackboard["b"] = 2
    del blackboard["a"]
    assert "b" in blackboard and "a" not in blackboard and len(blackboard) == 1 and blackboard["b"] == 2
    with pytest.raises(KeyError):
        blackboard["a"]


# --- Cancelling -----------------------------------------------------------------------------


def test_cancel_reaches_a_nested_state_and_ends_with_canceled_where_declared(yasmin) -> None:
    waiting = waiting_state(yasmin)
    inner = yasmin.StateMachine([SUCCEED, CANCEL])
    inner.add_state("wait", waiting)
    outer = yasmin.StateMachine([SUCCEED, ABORT, CANCEL])
    outer.add_state("nested", inner, transitions={SUCCEED: "after"})
    outer.add_state("after", record(yasmin, "after"))
    blackboard = yasmin.Blackboard()
    thread, result = run_in_thread(outer, blackboard)
    assert waiting.started.wait(WAIT_SECONDS)
    assert outer.get_current_state() == "nested" and inner.get_current_state() == "wait"
    outer.cancel_state()
    thread.join(WAIT_SECONDS)
    assert result == [CANCEL]
    assert waiting.is_canceled() and inner.is_canceled()
    assert "visited" not in blackboard  # "after" never ran


def test_a_canceled_outcome_the_machine_does_not_declare_is_an_error(yasmin) -> None:
    waiting = waiting_state(yasmin)
    machine = yasmin.StateMachine([SUCCEED])
    machine.add_state("wait", waiting)
    thread, result = run_in_thread(machine, yasmin.Blackboard())
    assert waiting.started.wait(WAIT_SECONDS)
    machine.cancel_state()
    thread.join(WAIT_SECONDS)
    assert len(result) == 1 and isinstance(result[0], KeyError)


def test_a_cancel_between_two_states_stops_the_machine_with_an_error(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])

    def cancel_own_machine(blackboard) -> str:
        machine.cancel_state()  # as if from another thread while this state runs
        return SUCCEED

    machine.add_state("stubborn", yasmin.CbState([SUCCEED], cancel_own_machine), {SUCCEED: "next"})
    machine.add_state("next", record(yasmin, "next"))
    blackboard = yasmin.Blackboard()
    with pytest.raises(RuntimeError):
        machine(blackboard)
    assert "visited" not in blackboard


def test_a_cancel_belongs_to_the_run_it_interrupted(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("only", record(yasmin, "only"))
    machine.cancel_state()
    assert machine() == SUCCEED and not machine.is_canceled()


# --- Mistakes --------------------------------------------------------------------------------


def test_an_undeclared_outcome_is_a_value_error_also_inside_a_machine(yasmin) -> None:
    state = yasmin.CbState([SUCCEED], lambda blackboard: "exploded")
    with pytest.raises(ValueError, match="exploded"):
        state()
    machine = yasmin.StateMachine([SUCCEED])
    machine.add_state("boom", yasmin.CbState([SUCCEED], lambda blackboard: "exploded"))
    with pytest.raises(ValueError, match="exploded"):
        machine()


def test_an_outcome_leading_nowhere_passes_validation_and_fails_when_taken(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED])
    machine.add_state("first", record(yasmin, "first", ABORT))  # ABORT: no transition, not an outcome
    machine.validate()
    with pytest.raises(KeyError):
        machine()
    with pytest.raises(KeyError):
        machine.validate(strict_mode=True)


def test_strict_validation_wants_every_outcome_of_the_machine_reached(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, "never"])
    machine.add_state("first", yasmin.CbState([SUCCEED], lambda bb: SUCCEED))
    machine.validate()
    with pytest.raises(KeyError):
        machine.validate(strict_mode=True)


def test_validation_rejects_an_unknown_target_and_an_empty_machine(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED])
    machine.add_state("first", record(yasmin, "first"), transitions={SUCCEED: "nowhere", ABORT: SUCCEED})
    with pytest.raises(KeyError):
        machine.validate()
    with pytest.raises(KeyError):
        machine()  # also on the first run
    with pytest.raises(RuntimeError):
        yasmin.StateMachine([SUCCEED]).validate()


def test_add_state_and_set_start_state_reject_mistakes_with_yasmins_errors(yasmin) -> None:
    machine = yasmin.StateMachine([SUCCEED, ABORT])
    machine.add_state("first", record(yasmin, "first"))
    with pytest.raises(KeyError):
        machine.add_state("first", record(yasmin, "again"))
    with pytest.raises(KeyError):
        machine.add_state(SUCCEED, record(yasmin, "clash"))
    with pytest.raises(KeyError):
        machine.add_state("second", record(yasmin, "second"), transitions={"not_an_outcome": SUCCEED})
    with pytest.raises(ValueError):
        machine.add_state("third", record(yasmin, "third"), transitions={SUCCEED: ""})
    with pytest.raises(ValueError):
        machine.set_start_state("")
    with pytest.raises(KeyError):
        machine.set_start_state("missing")
    with pytest.raises(ValueError):
        yasmin.CbState([], lambda blackboard: SUCCEED)


# --- What only the local implementation promises ---------------------------------------------


def test_local_errors_are_one_family_with_readable_messages() -> None:
    api = _local_api()
    machine = api.StateMachine([SUCCEED])
    machine.add_state("first", record(api, "first"))
    with pytest.raises(StateMachineError, match="already has a state named 'first'") as raised:
        machine.add_state("first", record(api, "again"))
    assert isinstance(raised.value, KeyError) and issubclass(StateMachineError, SailorError)
    assert str(raised.value).startswith("StateMachine(")  # not quoted, as a bare KeyError would be


def test_local_validation_reports_every_problem_at_once_and_inside_nested_machines() -> None:
    api = _local_api()
    inner = api.StateMachine([SUCCEED])
    inner.add_state("broken", record(api, "broken"), transitions={SUCCEED: "nowhere", ABORT: "elsewhere"})
    outer = api.StateMachine([SUCCEED])
    outer.add_state("nested", inner)
    with pytest.raises(StateMachineError, match=r"(?s)in state 'nested'.*nowhere.*in state 'nested'.*elsewhere"):
        outer.validate()


@pytest.mark.parametrize("outcomes", ["succeeded", [SUCCEED, SUCCEED], [""]])
def test_local_states_refuse_malformed_outcome_declarations(outcomes: object) -> None:
    with pytest.raises(ValueError):
        local_state.CbState(outcomes, lambda blackboard: SUCCEED)  # type: ignore[arg-type]


def test_local_state_without_execute_cannot_be_built() -> None:
    with pytest.raises(TypeError):
        local_state.State([SUCCEED])  # type: ignore[abstract]
