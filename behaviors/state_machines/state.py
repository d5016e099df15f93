"""A state: one step of a behaviour, which ends with one of the outcomes it declares.

The contract is YASMIN 3's Python one (``State(outcomes)``, ``execute(blackboard) -> outcome``,
``cancel_state()``), so behaviours written against it also run on the real package. Calling a
state, rather than its ``execute``, checks the outcome it returns against its declaration: a
state that returns something it never declared is a bug that would otherwise surface as a
confusing "no transition" far from its cause.
"""

import threading
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable

from merlin2_sailor_behaviors.state_machines.blackboard import Blackboard
from merlin2_sailor_behaviors.state_machines.errors import StateMachineValueError

StateCallback = Callable[[Blackboard], str]
"""What a :class:`CbState` runs: the blackboard in, an outcome out."""


def _declared_outcomes(outcomes: Iterable[str], owner: str) -> tuple[str, ...]:
    """Validate a declaration of outcomes: a non-empty sequence of distinct, non-empty strings."""
    if isinstance(outcomes, str):
        raise StateMachineValueError(f"{owner} outcomes must be a list of strings, got {outcomes!r}")
    declared = tuple(outcomes)
    if not declared:
        raise StateMachineValueError(f"{owner} must declare at least one outcome")
    bad = [outcome for outcome in declared if not isinstance(outcome, str) or not outcome]
    if bad:
        raise StateMachineValueError(f"{owner} outcomes must be non-empty strings, got {bad!r}")
    duplicates = sorted({outcome for outcome in declared if declared.count(outcome) > 1})
    if duplicates:
        raise StateMachineValueError(f"{owner} declares outcome(s) {duplicates} more than once")
    return declared


class State(ABC):
    """A step that ends with one of its declared outcomes; subclasses implement :meth:`execute`.

    A long-running ``execute`` should poll :meth:`is_canceled` and return ``canceled`` (declared
    among its outcomes) when it becomes true: cancellation is cooperative, as in YASMIN.
    """

    def __init__(self, outcomes: Iterable[str]) -> None:
        self._outcomes = _declared_outcomes(outcomes, type(self).__name__)
        self._canceled = threading.Event()
        self._running = threading.Event()

    @abstractmethod
    def execute(self, blackboard: Blackboard) -> str:
        """Do the state's work and return one of its outcomes."""

    def __call__(self, blackboard: Blackboard | None = None) -> str:
        """Run the state on a blackboard (a new one when None) and check its outcome.

        A cancellation requested before the run starts is forgotten: it was meant for a run
        that has ended.
        """
        self._begin_run()
        return self._run(Blackboard() if blackboard is None else blackboard)

    def _begin_run(self) -> None:
        """Forget an old cancellation. A machine calls this under its lock, before making the
        state its current one, so that a cancellation arriving from another thread just after
        cannot be wiped by the state starting up."""
        self._canceled.clear()

    def _run(self, blackboard: Blackboard) -> str:
        """Execute and check the outcome, without touching the cancellation flag."""
        self._running.set()
        try:
            outcome = self.execute(blackboard)
        finally:
            self._running.clear()
        if outcome not in self._outcomes:
            raise StateMachineValueError(
                f"{self} returned outcome {outcome!r}, which it does not declare; "
                f"declare it or return one of {list(self._outcomes)}"
            )
        return outcome

    def cancel_state(self) -> None:
        """Ask the running state to stop; it ends as soon as it next checks :meth:`is_canceled`."""
        self._canceled.set()

    def is_canceled(self) -> bool:
        """Whether :meth:`cancel_state` was called since this run started."""
        return self._canceled.is_set()

    def is_running(self) -> bool:
        """Whether the state is executing now."""
        return self._running.is_set()

    def get_outcomes(self) -> tuple[str, ...]:
        """The outcomes this state may end with, in declaration order."""
        return self._outcomes

    def __str__(self) -> str:
        return type(self).__name__


class CbState(State):
    """A state whose work is a plain function of the blackboard: the quickest way to a behaviour."""

    def __init__(self, outcomes: Iterable[str], cb: StateCallback) -> None:
        super().__init__(outcomes)
        if not callable(cb):
            raise StateMachineValueError(f"CbState cb must be callable, got {cb!r}")
        self._callback = cb

    def execute(self, blackboard: Blackboard) -> str:
        return self._callback(blackboard)

    def __str__(self) -> str:
        name = getattr(self._callback, "__name__", type(self._callback).__name__)
        return f"CbState({name})"
