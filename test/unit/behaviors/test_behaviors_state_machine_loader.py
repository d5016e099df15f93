"""Choosing the real yasmin package or the local implementation of its API.

The real package is not installable here, so the real path is exercised with stand-in modules
placed in ``sys.modules``; what matters is which classes the loader hands out.
"""

from __future__ import annotations

import os
import sys
import types

import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_behaviors import state_machines
from merlin2_sailor_behaviors.state_machines import loader
from merlin2_sailor_behaviors.state_machines.state import CbState
from merlin2_sailor_behaviors.state_machines.state_machine import StateMachine


@pytest.fixture
def no_yasmin(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``import yasmin`` fail as it does where YASMIN is not installed."""
    monkeypatch.setitem(sys.modules, "yasmin", None)
    monkeypatch.delenv(loader.SELECTION_VARIABLE, raising=False)


@pytest.fixture
def fake_yasmin(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    """A stand-in ``yasmin`` (and ``yasmin_ros.basic_outcomes``) with YASMIN's public names."""
    module = types.ModuleType("yasmin")
    for name in ("State", "CbState", "StateMachine", "Blackboard"):
        setattr(module, name, type(name, (), {}))
    outcomes = types.ModuleType("yasmin_ros.basic_outcomes")
    outcomes.SUCCEED, outcomes.ABORT, outcomes.CANCEL = "succeeded", "aborted", "canceled"
    monkeypatch.setitem(sys.modules, "yasmin", module)
    monkeypatch.setitem(sys.modules, "yasmin_ros", types.ModuleType("yasmin_ros"))
    monkeypatch.setitem(sys.modules, "yasmin_ros.basic_outcomes", outcomes)
    monkeypatch.delenv(loader.SELECTION_VARIABLE, raising=False)
    return module


@pytest.mark.usefixtures("no_yasmin")
def test_without_yasmin_the_local_implementation_is_used() -> None:
    assert not loader.use_real_yasmin()
    api = loader.load_state_machine_api()
    assert api.source == "local"
    assert api.StateMachine is StateMachine and api.CbState is CbState
    assert (api.SUCCEED, api.ABORT, api.CANCEL) == ("succeeded", "aborted", "canceled")


@pytest.mark.usefixtures("no_yasmin")
def test_asking_for_real_yasmin_where_it_is_missing_is_a_clear_error() -> None:
    with pytest.raises(ConfigurationError, match="cannot be imported"):
        loader.load_state_machine_api("real")


def test_with_yasmin_its_classes_are_exposed(fake_yasmin: types.ModuleType) -> None:
    assert loader.use_real_yasmin()
    api = loader.load_state_machine_api()
    assert api.source == "yasmin"
    assert api.State is fake_yasmin.State and api.StateMachine is fake_yasmin.StateMachine
    assert api.Blackboard is fake_yasmin.Blackboard and api.CANCEL == "canceled"


@pytest.mark.usefixtures("fake_yasmin")
def test_local_can_be_forced_where_yasmin_is_installed(monkeypatch: pytest.MonkeyPatch) -> None:
    assert loader.load_state_machine_api("local").source == "local"
    monkeypatch.setenv(loader.SELECTION_VARIABLE, "local")
    assert loader.load_state_machine_api().source == "local"


def test_an_unknown_selection_is_rejected() -> None:
    with pytest.raises(ConfigurationError, match="auto, local or real"):
        loader.load_state_machine_api("maybe")


def test_a_broken_yasmin_install_is_not_mistaken_for_a_missing_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def broken_import(name: str) -> types.ModuleType:
        raise ModuleNotFoundError("No module named 'yaml'", name="yaml")

    monkeypatch.setattr(loader.importlib, "import_module", broken_import)
    with pytest.raises(ModuleNotFoundError, match="yaml"):
        loader.use_real_yasmin()


def test_package_exports_the_api_the_environment_selects() -> None:
    # YASMIN is not on PyPI: the names are local unless this run asked for the real package (the
    # second pass of `make test` under SAILOR_UPSTREAM does).
    if os.environ.get(loader.SELECTION_VARIABLE) == "real":
        assert state_machines.IMPLEMENTATION == "yasmin"
        assert state_machines.StateMachine.__module__.startswith("yasmin")
        return
    assert state_machines.IMPLEMENTATION == "local"
    assert state_machines.StateMachine is StateMachine
