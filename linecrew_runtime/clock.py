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
MIN_WALL_PERIOD_S = 0.05
"""A periodic message keeps its mission-time rate under a speed-up, but is
never sent more than 20 times a wall second for it."""


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


def wall_period_s(period_s: float, speedup: float) -> float:
    """Wall seconds between two messages sent every ``period_s`` at x1, so
    that under ``speedup`` they stay that many mission seconds apart (others
    steer by them: at x10 a 0.5 s report would be 10 m of flight old); never
    below :data:`MIN_WALL_PERIOD_S` for it, never longer than ``period_s``."""
    return min(period_s, max(MIN_WALL_PERIOD_S, period_s / max(speedup, 1.0)))


def time_of_day(mission_s: float) -> str:
    """Mission seconds as the mission clock's time of day, ``HH:MM:SS`` (UTC)."""
    s = int(mission_s) % 86400
    return f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"
