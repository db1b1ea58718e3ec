"""The mission clock shared by every process of a (possibly sped-up) run.

Plans, holds and waits are in *mission seconds*. In a real deployment they
are UNIX seconds. When the simulator runs K times faster than real time,
every process is started with the same ``--speedup K`` and reads
``time.time() * K``: consistent across processes with no coordination, and
durations measured on it match the simulator's physics, energy and charging.
Link timeouts and watchdogs stay on the real monotonic clock.

``LINECREW_CLOCK_OFFSET_S`` (mission seconds, default 0) puts one process's
clock that far ahead (or behind, if negative) of the others: a machine whose
clock was stepped, as the chaos runner's ``clock_jump`` injects it.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable

OFFSET_ENV = "LINECREW_CLOCK_OFFSET_S"


def mission_clock(speedup: float = 1.0) -> Callable[[], float]:
    """A clock returning mission seconds (UNIX seconds times ``speedup``, plus
    the offset in ``LINECREW_CLOCK_OFFSET_S``)."""
    if speedup <= 0:
        raise ValueError(f"speedup must be positive, got {speedup}")
    offset = clock_offset_s()
    if speedup == 1.0 and offset == 0.0:
        return time.time
    return lambda: time.time() * speedup + offset


def clock_offset_s() -> float:
    """The mission seconds ``LINECREW_CLOCK_OFFSET_S`` asks for (0 when unset)."""
    raw = os.environ.get(OFFSET_ENV, "").strip()
    try:
        offset = float(raw) if raw else 0.0
    except ValueError:
        raise ValueError(f"{OFFSET_ENV} must be a number of seconds, got {raw!r}") from None
    if not math.isfinite(offset):
        raise ValueError(f"{OFFSET_ENV} must be finite, got {raw!r}")
    return offset


def time_of_day(mission_s: float) -> str:
    """Mission seconds as the mission clock's time of day, ``HH:MM:SS`` (UTC)."""
    s = int(mission_s) % 86400
    return f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"
