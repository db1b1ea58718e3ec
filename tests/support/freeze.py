"""Freeze one process of a running fleet for a block (the chaos runner's
partition of a loopback run: SIGSTOP, then SIGCONT whatever happens): it
falls silent exactly as if its link were cut."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator

from linecrew.chaos.faults import ProcessFaults
from linecrew.launch.local_run import LocalRun


@contextlib.contextmanager
def frozen(run: LocalRun, name: str) -> Iterator[float]:
    """Stop ``run``'s child ``name`` (e.g. ``agent-uav-1``) for the block;
    yields the monotonic time it was stopped."""
    faults = ProcessFaults(run)
    faults.cut(name)
    try:
        yield time.monotonic()
    finally:
        faults.heal(name)
