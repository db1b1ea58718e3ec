"""The onboard agent: the Agent Behavior Manager of one UAV.

A py_trees behaviour tree with the paper's structure executes the UAV's plan
over a MAVLink autopilot link and reports telemetry, status and task
outcomes over Zenoh. Run it with ``python -m onboard_agent`` (see
:func:`onboard_agent.main.main`).
"""

from onboard_agent.agent import Agent, UnknownUav
from onboard_agent.autopilot import (
    Autopilot,
    AutopilotError,
    CommandDenied,
    CommandTimeout,
    LinkLost,
    VehicleState,
)
from onboard_agent.config import AgentConfig
from onboard_agent.context import Context
from onboard_agent.idioms import main_tree
from onboard_agent.mission import Mission, PlanVerdict

__all__ = [
    "Agent",
    "AgentConfig",
    "Autopilot",
    "AutopilotError",
    "CommandDenied",
    "CommandTimeout",
    "Context",
    "LinkLost",
    "Mission",
    "PlanVerdict",
    "UnknownUav",
    "VehicleState",
    "main_tree",
]
