"""The mission clock shared by every process of a (possibly sped-up) run.

Plans, holds and waits are in *mission seconds*. In a real deployment they
are UNIX seconds. When the simulator runs K times faster than real time,
every process is started with the same ``--speedup K`` and reads
``time.time() * K``: consistent across processes with no coordination, and
durations measured on it match the simulator's physics, energy and charging.
Link timeouts and watchdogs stay on the real monotonic clock.
"""

from __future__ import annotations

import time
from collections.abc import Callable


def mission_clock(speedup: float = 1.0) -> Callable[[], float]:
    """A clock returning mission seconds (UNIX seconds times ``speedup``)."""
    if speedup <= 0:
        raise ValueError(f"speedup must be positive, got {speedup}")
    if speedup == 1.0:
        return time.time
    return lambda: time.time() * speedup
