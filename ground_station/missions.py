"""The mission manager: actions in, plans out.

It validates and stores operator requests (idempotent on the client's
request id, durable before the reply), hands agents' reports to
:class:`~ground_station.agent_reports.AgentReports`, and replans on every
trigger of the paper, sending a plan with a new epoch to each UAV whose work
changed. It does no I/O of its own besides the store: plans and events leave
through the callables given.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import msgspec

from ground_station import inventory
from ground_station.action_book import ActionBook
from ground_station.agent_reports import AgentReports
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import Change, FleetMonitor
from ground_station.lifecycle import TERMINAL, ActionEvent
from ground_station.replanner import Replanner
from ground_station.store import Store
from ground_station.validation import validate
from proto.errors import RequestError
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState, DeliverAction
from proto.plan import (
    MonitorTask,
    Plan,
)
from proto.rpc import (
    ActionList,
    ActionReply,
    CancelAction,
    FleetReply,
    GetAction,
    GetFleet,
    GetHistory,
    GetPlans,
    HistoryReply,
    ListActions,
    ModifyAction,
    PlansReply,
    Reply,
    Request,
    SubmitAction,
)
from proto.scenario import Scenario

log = logging.getLogger(__name__)


FLEET_EVENTS = {
    Change.LOST: EventKind.UAV_LOST,
    Change.BACK: EventKind.UAV_BACK,
    Change.CRASHED: EventKind.UAV_CRASHED,
    Change.FAILED: EventKind.UAV_LOST,
}
FLEET_TEXT = {
    Change.LOST: "silent past the link timeout; its work goes to others",
    Change.BACK: "heard again; it gets a fresh plan",
    Change.CRASHED: "telemetry says crashed; its work goes to others at once",
    Change.FAILED: "its agent reports failed; its work goes to others at once",
}


RETRY_UNPLACED_S = 30.0
"""Mission seconds between retries of actions that no UAV could take yet."""


class Conflict(RequestError):
    """A request id reused for a different request. Use a new request id."""

    code = "conflict"


class MissionManager:
    """Owns actions and plans; all methods run on the ground station's loop."""

    def __init__(
        self,
        *,
        scenario: Scenario,
        store: Store,
        monitor: FleetMonitor,
        events: EventLog,
        replanner: Replanner,
        clock: Callable[[], float],
        battery_margin_fraction: float = 0.1,
    ) -> None:
        self.scenario = scenario
        self.store = store
        self.monitor = monitor
        self.events = events
        self.replanner = replanner
        self.clock = clock
        self.book = ActionBook(store, events, clock)
        self._retried_s = clock()
        self.reports = AgentReports(
            scenario=scenario,
            book=self.book,
            monitor=monitor,
            events=events,
            replanner=replanner,
            replan=self.replan,
            battery_margin_fraction=battery_margin_fraction,
        )

    # -- requests --------------------------------------------------------------

    def handle(self, request: Request) -> Reply:
        """Answer one RPC request (raises a :class:`RequestError` to refuse)."""
        match request:
            case SubmitAction():
                return ActionReply(record=self.submit(request))
            case ModifyAction():
                return ActionReply(record=self.modify(request))
            case CancelAction():
                return ActionReply(record=self.cancel(request))
            case GetAction(action_id=action_id):
                return ActionReply(record=self.book.record(action_id))
            case ListActions(states=states):
                return ActionList(records=self.store.actions(states))
            case GetFleet():
                return FleetReply(uavs=self.monitor.snapshot())
            case GetPlans(uav_id=uav_id):
                plans = self.replanner.plans
                chosen = [plans[uav_id]] if uav_id in plans else [] if uav_id else plans.values()
                return PlansReply(plans=list(chosen))
            case GetHistory(after_seq=after, limit=limit):
                return HistoryReply(events=self.store.events(after, limit))
        raise RequestError(f"unsupported request {type(request).__name__}")

    def submit(self, request: SubmitAction) -> ActionRecord:
        """Accept an action: validated, stored durably, then planned."""
        existing = self.store.action_by_request(request.request_id)
        if existing is not None:
            if existing.action != request.action:
                raise Conflict("request_id already used for another action", field="request_id")
            return existing
        validate(request.action, self.scenario.site, self.scenario.fleet)
        if isinstance(request.action, DeliverAction):
            inventory.reserve(self.scenario.site, self.store.actions(), request.action)
        action_id = request.action_id or f"act-{self.store.next_counter('action'):05d}"
        if self.store.action(action_id) is not None:
            raise Conflict(f"action id {action_id!r} exists", field="action_id")
        now = self.clock()
        record = ActionRecord(
            action_id=action_id,
            action=request.action,
            state=ActionState.ACCEPTED,
            created_s=now,
            updated_s=now,
            request_id=request.request_id,
        )
        self.store.insert_action(record, now)
        self.events.emit(
            EventKind.ACTION_ACCEPTED, action_id=action_id, detail=type(request.action).__name__
        )
        self.replan(f"action {action_id} added")
        return self.book.record(action_id)

    def modify(self, request: ModifyAction) -> ActionRecord:
        """Change an action's priority and/or parameters, then replan."""
        record = self.book.live_record(request.action_id)
        action = request.action or record.action
        if type(action) is not type(record.action):
            raise RequestError(
                "cannot change an action's kind", code="invalid_action", field="action.type"
            )
        if request.priority is not None:
            action = msgspec.structs.replace(action, priority=request.priority)
        validate(action, self.scenario.site, self.scenario.fleet)
        if isinstance(action, DeliverAction):
            others = [r for r in self.store.actions() if r.action_id != record.action_id]
            inventory.reserve(self.scenario.site, others, action)
        self.book.save(msgspec.structs.replace(record, action=action), record.state, "modified")
        self.events.emit(EventKind.ACTION_CHANGED, action_id=record.action_id)
        self.replan(f"action {record.action_id} changed")
        return self.book.record(record.action_id)

    def cancel(self, request: CancelAction) -> ActionRecord:
        """Cancel an action (idempotent), then replan."""
        record = self.book.record(request.action_id)
        if record.state == ActionState.CANCELLED:
            return record
        self.book.transition(record, ActionEvent.CANCEL, "cancelled by operator")
        self.events.emit(EventKind.ACTION_CANCELLED, action_id=record.action_id)
        self.replan(f"action {record.action_id} cancelled")
        return self.book.record(record.action_id)

    # -- agents ----------------------------------------------------------------

    def on_fleet_changes(self, changes: list[tuple[str, Change]]) -> None:
        """A UAV was lost (after the grace), crashed, or came back: replan."""
        for uav_id, change in changes:
            self.events.emit(FLEET_EVENTS[change], uav_id=uav_id, detail=FLEET_TEXT[change])
            if change == Change.BACK:
                self.replanner.resend(uav_id)
            else:
                self._void_segments(uav_id)
        if changes:
            self.replan(", ".join(f"{u} {c}" for u, c in changes))
        for uav_id, change in changes:
            if change == Change.BACK:
                self.reports.release(uav_id)

    def _void_segments(self, uav_id: str) -> None:
        """A lost UAV's monitoring assignments end with the loss: its later
        segments get new ids, so its late report of the old ones is stale."""
        plan = self.replanner.plans.get(uav_id)
        watched = {t.action_id for t in plan.tasks if isinstance(t, MonitorTask)} if plan else set()
        for action_id in sorted(a for a in watched if a is not None):
            record = self.store.action(action_id)
            if self.book.in_force(record):
                assert record is not None
                segments = {**record.segments, uav_id: record.segments.get(uav_id, 0) + 1}
                self.book.save(
                    msgspec.structs.replace(record, segments=segments), record.state, "UAV lost"
                )

    def retry_unplaced(self) -> None:
        """Replan every ``RETRY_UNPLACED_S`` mission seconds while an action
        waits for a UAV: batteries filling on pads are no event, yet they
        make the action placeable (a replan that places nothing changes nothing)."""
        now = self.clock()
        if now - self._retried_s < RETRY_UNPLACED_S:
            return
        self._retried_s = now
        if self.store.actions([ActionState.ACCEPTED]):
            self.replan("retry of actions waiting for a UAV")

    # -- planning --------------------------------------------------------------

    def replan(self, reason: str) -> list[Plan]:
        """Plan the actions in force; returns the plans that changed."""
        records = self.store.actions(
            [ActionState.ACCEPTED, ActionState.PLANNED, ActionState.IN_PROGRESS]
        )
        outcome = self.replanner.replan(records, self.clock(), reason)
        for action_id, (event, reason_text) in outcome.action_events.items():
            record = self.store.action(action_id)
            if record is not None and record.state not in TERMINAL:
                self.book.transition(record, event, reason_text)
        return outcome.changed
