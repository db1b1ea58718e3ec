"""RPC between the gateway / CLI and the ground station.

Each request is sent as a Zenoh query on ``gs/rpc/{request.op}`` and answered
with one :data:`Reply`; failures come back as :class:`ErrorReply` (code,
message, offending field). State-changing requests carry a client
``request_id`` and are idempotent on it.
"""

from __future__ import annotations

import enum
import typing
from typing import ClassVar

from proto.base import Count, Finite, Id, Message, PositiveCount, Priority, Record, RequestId, Text
from proto.events import GsEvent
from proto.mission import Action, ActionRecord, ActionState
from proto.plan import Plan
from proto.telemetry import AgentStatus, Telemetry


class RequestBase(Message, frozen=True, kw_only=True):
    """Fields and the routing name (``op``) every request has."""

    op: ClassVar[str]


class SubmitAction(RequestBase, frozen=True, kw_only=True, tag="submit"):
    """Add an action. Replies :class:`ActionReply`."""

    op = "submit"
    request_id: RequestId
    action: Action
    action_id: Id | None = None  # a client-chosen id (else the ground station assigns one)


class ModifyAction(RequestBase, frozen=True, kw_only=True, tag="modify"):
    """Change an action's priority and/or parameters (same kind). Replies
    :class:`ActionReply`."""

    op = "modify"
    request_id: RequestId
    action_id: Id
    priority: Priority | None = None
    action: Action | None = None


class CancelAction(RequestBase, frozen=True, kw_only=True, tag="cancel"):
    """Cancel an action. Replies :class:`ActionReply`."""

    op = "cancel"
    request_id: RequestId
    action_id: Id


class GetAction(RequestBase, frozen=True, kw_only=True, tag="get_action"):
    """One action. Replies :class:`ActionReply`."""

    op = "get_action"
    action_id: Id


class ListActions(RequestBase, frozen=True, kw_only=True, tag="list_actions"):
    """Actions in creation order, optionally only those in ``states``, one
    page at a time: at most ``limit`` (and what fits the bus), after the
    action ``cursor`` names. Replies :class:`ActionList`."""

    op = "list_actions"
    states: list[ActionState] = []
    limit: PositiveCount | None = None
    cursor: Id | None = None


class GetFleet(RequestBase, frozen=True, kw_only=True, tag="fleet"):
    """The fleet's state. Replies :class:`FleetReply`."""

    op = "fleet"


class GetPlans(RequestBase, frozen=True, kw_only=True, tag="plans"):
    """Current plans (of one UAV if ``uav_id``). Replies :class:`PlansReply`."""

    op = "plans"
    uav_id: Id | None = None


class GetHistory(RequestBase, frozen=True, kw_only=True, tag="history"):
    """Events with ``seq > after_seq``, oldest first: at most ``limit`` and
    what fits the bus (ask again after the last one until none come).
    Replies :class:`HistoryReply`."""

    op = "history"
    after_seq: Count = 0
    limit: PositiveCount = 100


class GetMetrics(RequestBase, frozen=True, kw_only=True, tag="metrics"):
    """The ground station's counters and timings. Replies :class:`MetricsReply`."""

    op = "metrics"


class Command(enum.StrEnum):
    """What an operator orders a UAV to do, taking it out of the plan.

    ``hold``: hover where it is (stay on the pad if landed); ``return``: fly
    to its home station and land; ``land``: land where it is; ``resume``:
    back under the planner."""

    HOLD = "hold"
    RETURN = "return"
    LAND = "land"
    RESUME = "resume"


class ControlUav(RequestBase, frozen=True, kw_only=True, tag="control"):
    """Take control of ``uav_id`` (None: every UAV, e.g. ``hold`` as a fleet
    stop): its work goes to the others until ``resume``. Replies :class:`FleetReply`."""

    op = "control"
    uav_id: Id | None = None
    command: Command


Request = (
    SubmitAction
    | ModifyAction
    | CancelAction
    | GetAction
    | ListActions
    | GetFleet
    | GetPlans
    | GetHistory
    | GetMetrics
    | ControlUav
)
REQUEST_OPS: tuple[str, ...] = tuple(t.op for t in typing.get_args(Request))
"""The routing names of all requests, one queryable each."""


class UavOpState(enum.StrEnum):
    """A UAV's state as operators see it."""

    IDLE = "idle"
    BUSY = "busy"
    RECHARGING = "recharging"
    EMERGENCY = "emergency"
    NOT_READY = "not_ready"  # present, its autopilot cannot arm yet: takes no new work
    LOST = "lost"
    FAILED = "failed"


class UavState(Record, frozen=True, kw_only=True):
    """One UAV in a :class:`FleetReply`: state plus its latest reports."""

    uav_id: Id
    state: UavOpState
    telemetry: Telemetry | None = None
    status: AgentStatus | None = None
    silent_s: Finite | None = None
    """Seconds (on the watchdog's real-time clock) the UAV has been silent,
    while it is silent but within the link timeout (not yet lost); None when
    heard normally or already lost."""
    silent_since_s: Finite | None = None
    """When that silence began, in mission seconds of the ground station's
    clock (the clock of telemetry stamps); set with ``silent_s``."""
    unknown_tasks: list[Id] = []
    """While silent: the ids of its planned tasks (the one it was running
    and those after it) whose fate is unknown: neither failed nor known to
    run. Heard again, they are what its reports say; lost, they go to others."""
    control: Command | None = None
    """The operator's command in force (None: the planner flies it)."""


class ActionReply(Message, frozen=True, kw_only=True, tag="action"):
    """One action record."""

    record: ActionRecord


class ActionList(Message, frozen=True, kw_only=True, tag="actions"):
    """Action records; ``next_cursor`` continues the list (None: it ended)."""

    records: list[ActionRecord]
    next_cursor: Id | None = None


class FleetReply(Message, frozen=True, kw_only=True, tag="fleet"):
    """Every UAV's state."""

    uavs: list[UavState]


class PlansReply(Message, frozen=True, kw_only=True, tag="plans"):
    """Current plans and the live plan's quality: its objective (seconds:
    weight-averaged completion + makespan), mission seconds since an
    improvement was adopted, and its gap to the best plan seen for the same
    state (a fraction); None where not known yet."""

    plans: list[Plan]
    objective_s: Finite | None = None
    improved_ago_s: Finite | None = None
    gap_to_best: Finite | None = None


class HistoryReply(Message, frozen=True, kw_only=True, tag="history"):
    """Events, oldest first, and the newest ``seq`` the ground station has
    numbered (the end of the log, whatever ``after_seq`` asked)."""

    events: list[GsEvent]
    last_seq: Count = 0


class ErrorReply(Message, frozen=True, kw_only=True, tag="error"):
    """A typed failure: stable ``code``, human ``message``, offending ``field``."""

    code: Text
    message: Text
    field: Text | None = None


class MetricsReply(Message, frozen=True, kw_only=True, tag="metrics"):
    """Named numbers (counts, seconds) of the ground station."""

    values: dict[str, float]


Reply = (
    ActionReply | ActionList | FleetReply | PlansReply | HistoryReply | MetricsReply | ErrorReply
)
