"""Values that vehicles hand to their MAVLink endpoint: command results, texts."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class Result(IntEnum):
    """MAV_RESULT."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5


class Severity(IntEnum):
    """MAV_SEVERITY."""

    EMERGENCY = 0
    ALERT = 1
    CRITICAL = 2
    ERROR = 3
    WARNING = 4
    NOTICE = 5
    INFO = 6
    DEBUG = 7


@dataclass(frozen=True, slots=True)
class StatusText:
    severity: Severity
    text: str  # at most 50 characters reach the wire (STATUSTEXT)


@dataclass(frozen=True, slots=True)
class Outcome:
    """What a command did; ``text`` (if any) goes out as STATUSTEXT first."""

    result: Result
    text: str | None = None


ACCEPTED = Outcome(Result.ACCEPTED)
