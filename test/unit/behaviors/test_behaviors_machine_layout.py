"""A running machine's layout for the YASMIN viewer, on the local implementation and real YASMIN."""

from __future__ import annotations

import threading

import pytest

from merlin2_sailor_behaviors.actions.machine_layout import NO_STATE, machine_layout
from merlin2_sailor_behaviors.state_machines import state as local_state
from merlin2_sailor_behaviors.state_machines import state_machine as local_state_machine
from merlin2_sailor_behaviors.state_machines.outcomes import ABORT, CANCEL, SUCCEED


@pytest.fixture(params=["local", "yasmin"])
def api(request: pytest.FixtureRequest, upstream_stack):  # noqa: ANN201
    if request.param == "local":
        return local_state.CbState, local_state_machine.StateMachine
    upstream_stack("yasmin")
    import yasmin

    return yasmin.CbState, yasmin.StateMachine


def test_the_layout_lists_every_level_with_parents_transitions_and_the_running_state(api) -> None:
    CbState, StateMachine = api
    inside = threading.Event()
    layouts: list = []
    outer = StateMachine([SUCCEED, ABORT, CANCEL])

    def look(blackboard) -> str:
        layouts.append(machine_layout("find_object", outer))
        inside.set()
        return SUCCEED

    inner = StateMachine([SUCCEED, ABORT])
    inner.add_state("LOOK", CbState([SUCCEED, ABORT], look))
    outer.add_state("GO", CbState([SUCCEED, ABORT], lambda bb: SUCCEED), {SUCCEED: "SEARCH"})
    outer.add_state("SEARCH", inner)
    outer()
    assert inside.is_set()
    root, go, search, look_state = layouts[0]
    assert (root.id, root.parent, root.name, root.is_fsm) == (0, NO_STATE, "find_object", True)
    assert root.current_state == search.id and root.outcomes == sorted([SUCCEED, ABORT, CANCEL])
    assert (go.parent, go.transitions, go.is_fsm) == (root.id, {SUCCEED: "SEARCH"}, False)
    assert (search.parent, search.is_fsm, search.current_state) == (root.id, True, look_state.id)
    assert (look_state.parent, look_state.name) == (search.id, "LOOK")
    # Between runs, no state is current.
    assert machine_layout("find_object", outer)[0].current_state == NO_STATE
