"""What agents and the human tracker report: telemetry, agent status,
task outcomes and human poses. Times (``stamp_s``) are mission seconds:
UNIX seconds in the field, UNIX seconds times K in a simulation run at
``--speedup K`` (:mod:`linecrew_runtime.clock`), for every sender alike.
"""

from __future__ import annotations

import enum
from typing import Annotated

import msgspec

from proto.base import Count, Finite, Fraction, Id, Message, NonNegative, Record, Text
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
    stamp_s: Finite
    position: Point
    geo: GeoPoint
    velocity: Vector = Vector()
    heading_deg: Finite = 0.0
    battery_wh: NonNegative
    battery_fraction: Fraction
    flight_state: FlightState = FlightState.UNKNOWN
    armed: bool = False
    mode: Text = ""
    tool: Id | None = None
    target: Point | None = None
    """The position target the agent last sent its autopilot (None on the
    ground and while taking off): a UAV whose agent hangs flies on to it."""


class TrafficEntry(Record, frozen=True, kw_only=True):
    """One UAV as the ground station last heard it, ``age_s`` before the
    report was sent: where it was and the position target it was flying to
    (where it may be by now if it is no longer heard)."""

    uav_id: Id
    position: Point
    airborne: bool
    age_s: NonNegative = 0.0
    target: Point | None = None


class Traffic(Message, frozen=True, kw_only=True):
    """Where the fleet's UAVs are, from the ground station on ``gs/traffic``
    twice a mission second (at most 20 times a wall second): agents keep
    clear of points another UAV hovers at.

    It also announces the ground station: ``generation`` (one id per
    ground-station run) and ``epoch``, the newest plan epoch it has issued.
    An agent adopts a plan whose epoch runs far ahead of what was announced
    only once an announcement covers it."""

    uavs: list[TrafficEntry] = []
    generation: Id | None = None
    epoch: Count = 0


class AgentState(enum.StrEnum):
    """The agent's own view of itself, as operators see it."""

    IDLE = "idle"
    BUSY = "busy"
    RECHARGING = "recharging"
    EMERGENCY = "emergency"
    FAILED = "failed"
    NOT_READY = "not_ready"  # autopilot up but cannot arm yet (GPS, EKF, home, pre-arm)


class AgentStatus(Message, frozen=True, kw_only=True):
    """Published by each agent at 1 Hz and on change on ``uav/{id}/status``."""

    uav_id: Id
    stamp_s: Finite
    state: AgentState
    epoch: Count = 0
    task_id: Id | None = None
    progress: Fraction = 0.0
    active_path: Annotated[list[Text], msgspec.Meta(max_length=64)] = []
    queue_length: Count = 0
    reason: Text = ""
    ready: bool = True  # False while the autopilot cannot arm (``reason`` says why)
    holding_for: Id | None = None
    """Another UAV at the point this one flies to next: it holds where it is
    until that point is free (keep-clear, at most the agent's yield time)."""


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
    ``retryable`` marks a failure for a passing reason (the autopilot was not
    ready or refused to arm, a command timed out, an emergency emptied the
    queue): the same task can succeed later or on another UAV. Otherwise a
    failure is permanent. ``reason_code`` is a short machine-readable code
    (``not_ready``, ``arm_refused``, ``command_timeout``, ``abandoned``,
    ``invalid_task``, ``wrong_uav``, ``task_failed``; "" when completed).
    """

    uav_id: Id
    task_id: Id
    action_id: Id | None = None
    epoch: Count
    result: OutcomeResult
    reason: Text = ""
    progress: Fraction = 1.0
    waypoints_done: list[int] = []
    stamp_s: Finite = 0.0
    flown_s: NonNegative = 0.0
    tool: Id | None = None
    retryable: bool = False
    reason_code: Text = ""


POSE_FUTURE_S = 5.0
"""A worker pose stamped more than this ahead of the reader's real-time clock
is refused (a forged one would otherwise outrank every real pose)."""


class HumanPose(Message, frozen=True, kw_only=True):
    """A worker's position from the human tracker, on ``human/{id}/pose``.
    ``stamp_s`` is on the mission clock, as telemetry is (a simulated
    tracker lives in the sped-up world)."""

    worker_id: Id
    stamp_s: Finite
    position: Point
    geo: GeoPoint
