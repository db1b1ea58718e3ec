"""What the chaos runner does to the processes of a run: ``kill -9`` and
restart with the same arguments, and partitions.

On a :class:`~linecrew.chaos.netns_run.NetnsRun` a partition is a real cut
of the process's Zenoh link (nft in its namespace), healed by removing the
rule; every side notices the silence and acts on its own rules (an agent
abandons its tasks and lands at a station after its grace).

On loopback (:class:`~linecrew.launch.local_run.LocalRun`) a partition is
emulated by freezing the process (SIGSTOP, healed by SIGCONT): it stops
talking exactly like a cut link, so the others see the same silence, loss,
replan and return. What it does not reproduce is the frozen process's own
side: a frozen agent cannot notice the silence, so it neither abandons its
tasks nor lands (its vehicle hovers at its last set-point, draining its
battery: the runner excuses a later dip below reserve on that UAV); a
frozen ground station does not declare anyone lost meanwhile. A frozen
gateway would also stall the observer's own REST calls, so the runner does
not partition the gateway on loopback.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
from collections.abc import Mapping
from typing import cast

from linecrew.chaos.netns_run import NetnsRun
from linecrew.launch.local_run import LocalRun
from linecrew.launch.supervisor import Child

log = logging.getLogger(__name__)


class ProcessFaults:
    """Kill, restart, cut off and heal the named children of ``run``."""

    def __init__(self, run: LocalRun | NetnsRun) -> None:
        self.run = run
        self.real_cuts = isinstance(run, NetnsRun)
        self.cut_off: set[str] = set()
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

    def restart(self, name: str, env: Mapping[str, str] | None = None) -> Child:
        """Start ``name`` again with its arguments (in its namespace, if any) and
        ``env`` added to the environment; the old log is kept as ``name.N.log``."""
        old = self.child(name)
        if old.alive():
            raise RuntimeError(f"{name} is still running")
        count = self._restarts[name] = self._restarts.get(name, 0) + 1
        if old.log_path.exists():
            old.log_path.rename(old.log_path.with_name(f"{name}.{count}.log"))
        # Supervisor.start runs a list: [prefix..., python, -m, module, *args]
        args = [str(a) for a in cast(list[str], old.popen.args)]
        module = args.index("-m") + 1
        return self.run.supervisor.start(name, args[module], *args[module + 1 :], env=env)

    def cut(self, name: str) -> None:
        """Partition ``name``: its link cut (a namespace run) or the process frozen."""
        if isinstance(self.run, NetnsRun):
            self.run.cut(name)
        else:
            os.kill(self.child(name).popen.pid, signal.SIGSTOP)
        self.cut_off.add(name)

    def heal(self, name: str) -> None:
        """The link is back (the rule removed, or SIGCONT)."""
        if name not in self.cut_off:
            return
        self.cut_off.discard(name)
        if isinstance(self.run, NetnsRun):
            self.run.heal(name)
            return
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.child(name).popen.pid, signal.SIGCONT)

    def heal_all(self) -> None:
        """Heal whatever is still cut off (before stopping the run)."""
        for name in sorted(self.cut_off):
            self.heal(name)
