"""``linecrew chaos``: a seeded random mix of partitions, kills, battery
faults and new actions injected into a local fleet, with the system's
invariants checked continuously (entry point :func:`main`)."""

from linecrew.chaos.invariants import Checker, Violation
from linecrew.chaos.main import main
from linecrew.chaos.runner import ChaosOptions, ChaosResult, ChaosRunner
from linecrew.chaos.schedule import Injection, make_schedule

__all__ = [
    "ChaosOptions",
    "ChaosResult",
    "ChaosRunner",
    "Checker",
    "Injection",
    "Violation",
    "main",
    "make_schedule",
]
