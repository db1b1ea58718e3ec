"""Errors of the autopilot link.

::

    LinecrewError
    └── AutopilotError        "autopilot_error"
        ├── CommandDenied     "autopilot_command_denied"   the autopilot refused (MAV_RESULT)
        ├── CommandTimeout    "autopilot_command_timeout"  no COMMAND_ACK after the retries
        └── LinkLost          "autopilot_link_lost"        no heartbeat from the autopilot

Raised (as the exception of a command's future) by :mod:`onboard_agent.autopilot.link`
and the fakes; a behaviour that sees one fails with the error as its feedback.
"""

from __future__ import annotations

from proto.errors import LinecrewError


class AutopilotError(LinecrewError):
    """Something the autopilot did or did not do. Behaviours fail on it; the
    tree decides what to try next."""

    code = "autopilot_error"


class CommandDenied(AutopilotError):
    """The autopilot answered a command with a result other than ACCEPTED.
    Retrying the same command in the same state gives the same answer."""

    code = "autopilot_command_denied"

    def __init__(self, command: str, result: str, reason: str = "") -> None:
        text = f"{command} {result}" + (f": {reason}" if reason else "")
        super().__init__(text)
        self.command = command
        self.result = result
        self.reason = reason


class CommandTimeout(AutopilotError):
    """No COMMAND_ACK after all retries: the link is bad or the autopilot busy.
    Safe to retry later."""

    code = "autopilot_command_timeout"


class LinkLost(AutopilotError):
    """No heartbeat from the autopilot within the timeout: escalate (the UAV
    is reported failed)."""

    code = "autopilot_link_lost"
