"""What every agent behaviour shares: the context, and a slot for one
autopilot command in flight.

``update()`` never blocks: a behaviour issues a command (which returns a
:class:`~onboard_agent.autopilot.protocol.Pending`) and checks it on the
following ticks.
"""

from __future__ import annotations

import py_trees

from onboard_agent.autopilot.protocol import Pending
from onboard_agent.context import Context

Status = py_trees.common.Status


class AgentBehaviour(py_trees.behaviour.Behaviour):
    """A behaviour with the agent's :class:`Context`. ``kind`` is the node
    category in the BehaviorTree.CPP export (Action or Condition)."""

    kind = "Action"

    def __init__(self, name: str, ctx: Context) -> None:
        super().__init__(name)
        self.ctx = ctx
        # set by a behaviour that fails, for the task guard: a short code, and
        # whether the reason is passing (retry later or elsewhere)
        self.failure_code = ""
        self.retryable = False


class Condition(AgentBehaviour):
    """A check: SUCCESS if ``holds()``, else FAILURE; never RUNNING."""

    kind = "Condition"

    def holds(self) -> bool:
        raise NotImplementedError

    def update(self) -> Status:
        result = self.holds()
        self.feedback_message = "yes" if result else "no"
        return Status.SUCCESS if result else Status.FAILURE


class CommandSlot:
    """One autopilot command in flight, and what it was."""

    def __init__(self) -> None:
        self._pending: Pending | None = None
        self.label = ""
        self.error = ""
        self.failed: BaseException | None = None  # the exception of the last failure
        self.failed_label = ""  # what failed last

    def issue(self, label: str, pending: Pending) -> None:
        if self._pending is not None:
            _forget(self._pending)
        self.label, self._pending, self.error = label, pending, ""
        self.failed, self.failed_label = None, ""

    def check(self) -> Status:
        """RUNNING while in flight; SUCCESS when acknowledged (or when none
        was issued); FAILURE with ``error`` when refused or timed out."""
        pending = self._pending
        if pending is None:
            return Status.SUCCESS
        if not pending.done():
            return Status.RUNNING
        self._pending = None
        if pending.cancelled():
            self.failed_label = self.label
            self.error, self.label = f"{self.label}: cancelled", ""
            return Status.FAILURE
        exc = pending.exception()
        if exc is not None:
            self.failed, self.failed_label = exc, self.label
            self.error, self.label = str(exc), ""
            return Status.FAILURE
        return Status.SUCCESS

    def cancel(self) -> None:
        if self._pending is not None:
            _forget(self._pending)
        self._pending = None
        self.label = ""


def _forget(pending: Pending) -> None:
    """Drop a command nobody waits for any more (cancelled if still in
    flight) without leaving an exception unretrieved ("Task exception was
    never retrieved" in the agent's log)."""
    if not pending.done():
        pending.cancel()
        pending.add_done_callback(_retrieve)
    else:
        _retrieve(pending)


def _retrieve(pending: Pending) -> None:
    if not pending.cancelled():
        pending.exception()
