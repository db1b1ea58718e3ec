"""Operator actions (what the crew asks for) and their lifecycle records."""

from __future__ import annotations

import enum

from proto.base import (
    Bearing,
    Finite,
    Fraction,
    Id,
    NonNegative,
    Positive,
    PositiveCount,
    Priority,
    Record,
    RequestId,
    Text,
)
from proto.geo import Point


class ActionBase(Record, frozen=True, kw_only=True):
    """Fields every action has.

    ``priority`` is the weight of the FCFS queue (higher first);
    ``release_s`` is the earliest start (mission seconds, see :mod:`proto.telemetry`; 0 = now).
    """

    priority: Priority = 1.0
    release_s: NonNegative = 0.0


class WaypointSpec(Record, frozen=True, kw_only=True):
    """One point to inspect and how long to hold there (seconds)."""

    position: Point
    service_s: NonNegative = 0.0


class InspectAction(ActionBase, frozen=True, kw_only=True, tag="inspect"):
    """Inspect ``waypoints``; the planner may split them among UAVs."""

    waypoints: list[WaypointSpec]


class MonitorAction(ActionBase, frozen=True, kw_only=True, tag="monitor"):
    """Watch ``worker_id`` with ``uavs`` UAVs at ``standoff_m`` for ``duration_s``.

    ``bearing_deg`` is the bearing of slot 0 in degrees, counter-clockwise
    from the site's +x axis (east); the other slots follow at 360/uavs
    apart. Left out, the ground station picks the bearing farthest from the
    slots of the worker's other monitoring actions in force, so that two of
    them never send UAVs to one point; the stored action holds the choice."""

    worker_id: Id
    uavs: PositiveCount = 1
    standoff_m: Positive = 5.0
    duration_s: Positive
    bearing_deg: Bearing | None = None


class DeliverAction(ActionBase, frozen=True, kw_only=True, tag="deliver"):
    """Bring ``tool`` from ``tool_station_id`` to ``worker_id``."""

    tool: Id
    tool_station_id: Id
    worker_id: Id
    pick_s: NonNegative = 5.0
    drop_s: NonNegative = 5.0


Action = InspectAction | MonitorAction | DeliverAction


class ActionState(enum.StrEnum):
    """Lifecycle of an action at the ground station."""

    ACCEPTED = "accepted"
    PLANNED = "planned"
    IN_PROGRESS = "in_progress"
    COMPLETED = "completed"
    FAILED = "failed"
    CANCELLED = "cancelled"


class ActionRecord(Record, frozen=True, kw_only=True):
    """An action as the ground station holds it.

    Partial progress: ``waypoints_done`` (inspection waypoint indices already
    inspected, so a split inspection resumes) and ``monitored_s`` (seconds of
    monitoring already covered). ``segments`` counts the monitoring segments
    each UAV has ended, so that a later segment gets a new task id and is
    never mistaken for the one already flown. ``slot_bearings_deg`` holds
    the monitoring slots moved off their place on the ring (slot -> its
    bearing in degrees) because a UAV lost in the air there may hover on.
    """

    action_id: Id
    action: Action
    state: ActionState
    progress: Fraction = 0.0
    created_s: Finite = 0.0
    updated_s: Finite = 0.0
    reason: Text = ""
    request_id: RequestId | None = None
    waypoints_done: list[int] = []
    monitored_s: NonNegative = 0.0
    segments: dict[str, int] = {}
    slot_bearings_deg: dict[int, float] = {}
