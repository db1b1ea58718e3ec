"""Freeze one process of a running fleet for a block (SIGSTOP, then SIGCONT
whatever happens): it falls silent exactly as if its link were cut."""

from __future__ import annotations

import contextlib
import os
import signal
import time
from collections.abc import Iterator

from linecrew.launch.local_run import LocalRun


@contextlib.contextmanager
def frozen(run: LocalRun, name: str) -> Iterator[float]:
    """Stop ``run``'s child ``name`` (e.g. ``agent-uav-1``) for the block;
    yields the monotonic time it was stopped."""
    child = next(c for c in reversed(run.supervisor.children) if c.name == name)
    os.kill(child.popen.pid, signal.SIGSTOP)
    try:
        yield time.monotonic()
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(child.popen.pid, signal.SIGCONT)
