"""The autopilot seam: a protocol the tree uses and its MAVLink implementation."""

from onboard_agent.autopilot.errors import AutopilotError, CommandDenied, CommandTimeout, LinkLost
from onboard_agent.autopilot.protocol import GUIDED, LAND, Autopilot, Pending, VehicleState

__all__ = [
    "GUIDED",
    "LAND",
    "Autopilot",
    "AutopilotError",
    "CommandDenied",
    "CommandTimeout",
    "LinkLost",
    "Pending",
    "VehicleState",
]
