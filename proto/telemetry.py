"""What agents and the human tracker report: telemetry, agent status,
task outcomes and human poses. Times are UNIX seconds (``stamp_s``).
"""

from __future__ import annotations

import enum

from proto.base import Count, Fraction, Id, Message, NonNegative
from proto.geo import GeoPoint, Point, Vector


class FlightState(enum.StrEnum):
    """Where the vehicle is in its flight."""

    LANDED = "landed"
    TAKING_OFF = "taking_off"
    FLYING = "flying"
    LANDING = "landing"
    CRASHED = "crashed"
    UNKNOWN = "unknown"


class Telemetry(Message, frozen=True, kw_only=True):
    """Published by each agent at about 5 Hz on ``uav/{id}/telemetry``."""

    uav_id: Id
    stamp_s: float
    position: Point
    geo: GeoPoint
    velocity: Vector = Vector()
    heading_deg: float = 0.0
    battery_wh: NonNegative
    battery_fraction: Fraction
    flight_state: FlightState = FlightState.UNKNOWN
    armed: bool = False
    mode: str = ""
    tool: Id | None = None


class AgentState(enum.StrEnum):
    """The agent's own view of itself, as operators see it."""

    IDLE = "idle"
    BUSY = "busy"
    RECHARGING = "recharging"
    EMERGENCY = "emergency"
    FAILED = "failed"


class AgentStatus(Message, frozen=True, kw_only=True):
    """Published by each agent at 1 Hz and on change on ``uav/{id}/status``."""

    uav_id: Id
    stamp_s: float
    state: AgentState
    epoch: Count = 0
    task_id: Id | None = None
    progress: Fraction = 0.0
    active_path: list[str] = []
    queue_length: Count = 0
    reason: str = ""


class OutcomeResult(enum.StrEnum):
    """How a task ended."""

    COMPLETED = "completed"
    FAILED = "failed"
    ABORTED = "aborted"


class TaskOutcome(Message, frozen=True, kw_only=True):
    """An agent's report that a task ended, on ``uav/{id}/outcome``.

    ``epoch`` is the plan epoch the task came from (stale epochs are recorded
    but change nothing). ``waypoints_done`` lists inspection waypoint indices
    visited, so a split inspection resumes where it stopped. ``flown_s`` is
    the time spent on station for a monitoring task, measured on board: the
    ground station credits that, not the planned duration. ``tool`` is the
    tool the gripper grabbed (pick) or released (drop), as the agent saw it.
    """

    uav_id: Id
    task_id: Id
    action_id: Id | None = None
    epoch: Count
    result: OutcomeResult
    reason: str = ""
    progress: Fraction = 1.0
    waypoints_done: list[int] = []
    stamp_s: float = 0.0
    flown_s: NonNegative = 0.0
    tool: Id | None = None


class HumanPose(Message, frozen=True, kw_only=True):
    """A worker's position from the human tracker, on ``human/{id}/pose``."""

    worker_id: Id
    stamp_s: float
    position: Point
    geo: GeoPoint
