"""What the chaos runner does to the processes of a :class:`LocalRun`:
``kill -9`` and restart with the same arguments, and partitions.

A partition on loopback is emulated by freezing the agent (SIGSTOP, healed
by SIGCONT): a frozen process stops talking exactly like a cut link, so the
ground station sees the same silence, loss, replan and return. What it does
not reproduce is the agent's own side: a frozen agent cannot notice the
silence, so it neither abandons its tasks nor lands while cut off (its
vehicle hovers at its last set-point, draining its battery); the runner
therefore excuses a later dip below reserve on that UAV. The network-
namespace tests (``tests/chaos/test_netns_partitions.py``) cover the
agent's side with real cut links.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal

from linecrew.launch.local_run import LocalRun
from linecrew.launch.supervisor import Child

log = logging.getLogger(__name__)


class ProcessFaults:
    """Kill, restart, freeze and thaw the named children of ``run``."""

    def __init__(self, run: LocalRun) -> None:
        self.run = run
        self.frozen: set[str] = set()
        self._restarts: dict[str, int] = {}

    def child(self, name: str) -> Child:
        """The newest child called ``name`` (``router``, ``ground-station``, ``agent-uav-1``)."""
        return next(c for c in reversed(self.run.supervisor.children) if c.name == name)

    def kill(self, name: str) -> int:
        """``kill -9`` the child; its pid."""
        child = self.child(name)
        with contextlib.suppress(ProcessLookupError):
            os.kill(child.popen.pid, signal.SIGKILL)
        child.popen.wait()
        return child.popen.pid

    def restart(self, name: str) -> Child:
        """Start ``name`` again with its arguments; the old log is kept as ``name.N.log``."""
        old = self.child(name)
        if old.alive():
            raise RuntimeError(f"{name} is still running")
        count = self._restarts[name] = self._restarts.get(name, 0) + 1
        if old.log_path.exists():
            old.log_path.rename(old.log_path.with_name(f"{name}.{count}.log"))
        args = [str(a) for a in old.popen.args]  # [python, -m, module, *args]
        return self.run.supervisor.start(name, args[2], *args[3:])

    def freeze(self, name: str) -> None:
        """SIGSTOP: the process goes silent as if its link were cut."""
        os.kill(self.child(name).popen.pid, signal.SIGSTOP)
        self.frozen.add(name)

    def thaw(self, name: str) -> None:
        """SIGCONT: the link is back."""
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.child(name).popen.pid, signal.SIGCONT)
        self.frozen.discard(name)

    def thaw_all(self) -> None:
        """Thaw whatever is still frozen (before stopping the run)."""
        for name in sorted(self.frozen):
            self.thaw(name)
