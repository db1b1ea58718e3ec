"""The mission manager: actions in, plans out.

It validates and stores operator requests (idempotent on the client's
request id, durable before the reply), applies agents' outcomes to actions
(fencing stale ones), and replans on every trigger of the paper, sending a
plan with a new epoch to each UAV whose work changed. It does no I/O of its
own besides the store: plans and events leave through the callables given.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable

import msgspec

from ground_station.event_log import EventLog
from ground_station.fleet_monitor import Change, FleetMonitor
from ground_station.lifecycle import TERMINAL, ActionEvent, next_state
from ground_station.progress import apply_outcome
from ground_station.replanner import Replanner
from ground_station.store import Store
from ground_station.validation import validate
from proto.errors import RequestError
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState
from proto.plan import Plan
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
from proto.telemetry import TaskOutcome, Telemetry

log = logging.getLogger(__name__)


class NotFound(RequestError):
    """An action id the ground station does not know. Do not retry."""

    code = "not_found"


class Conflict(RequestError):
    """A request id reused for a different request. Use a new request id."""

    code = "conflict"


@dataclasses.dataclass
class Counters:
    """What the ground station counts, readable over RPC later."""

    outcomes: int = 0
    stale_outcomes: int = 0
    battery_replans: int = 0


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
        self.battery_margin_fraction = battery_margin_fraction
        self.counters = Counters()
        self._battery_flagged: dict[str, int] = {}

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
                return ActionReply(record=self._record(action_id))
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
        return self._record(action_id)

    def modify(self, request: ModifyAction) -> ActionRecord:
        """Change an action's priority and/or parameters, then replan."""
        record = self._live_record(request.action_id)
        action = request.action or record.action
        if type(action) is not type(record.action):
            raise RequestError(
                "cannot change an action's kind", code="invalid_action", field="action.type"
            )
        if request.priority is not None:
            action = msgspec.structs.replace(action, priority=request.priority)
        validate(action, self.scenario.site, self.scenario.fleet)
        self._save(msgspec.structs.replace(record, action=action), record.state, "modified")
        self.events.emit(EventKind.ACTION_CHANGED, action_id=record.action_id)
        self.replan(f"action {record.action_id} changed")
        return self._record(record.action_id)

    def cancel(self, request: CancelAction) -> ActionRecord:
        """Cancel an action (idempotent), then replan."""
        record = self._record(request.action_id)
        if record.state == ActionState.CANCELLED:
            return record
        self._transition(record, ActionEvent.CANCEL, "cancelled by operator")
        self.events.emit(EventKind.ACTION_CANCELLED, action_id=record.action_id)
        self.replan(f"action {record.action_id} cancelled")
        return self._record(record.action_id)

    # -- agents ----------------------------------------------------------------

    def on_outcome(self, outcome: TaskOutcome) -> None:
        """Apply an agent's outcome; stale ones are recorded only."""
        self.counters.outcomes += 1
        plan = self.replanner.plans.get(outcome.uav_id)
        task = next((t for t in plan.tasks if t.task_id == outcome.task_id), None) if plan else None
        if task is None or (plan is not None and outcome.epoch > plan.epoch):
            self.counters.stale_outcomes += 1
            self.events.emit(
                EventKind.FAULT,
                uav_id=outcome.uav_id,
                epoch=outcome.epoch,
                detail=f"stale outcome {outcome.task_id} {outcome.result}",
            )
            return
        if task.action_id is not None:
            record = self.store.action(task.action_id)
            if record is not None and record.state not in TERMINAL:
                updated, event = apply_outcome(record, task, outcome)
                self._save(updated, record.state, f"{outcome.task_id} {outcome.result}")
                if event is not None:
                    self._transition(updated, event, f"{outcome.task_id} {outcome.result}")
        self.replan(f"{outcome.uav_id} {outcome.task_id} {outcome.result}")

    def on_telemetry(self, telemetry: Telemetry) -> None:
        """Replan once per plan if the battery is below the plan's estimate by a margin."""
        plan = self.replanner.plans.get(telemetry.uav_id)
        uav_type = self.scenario.fleet.type_of(telemetry.uav_id)
        if not plan or not plan.tasks or uav_type is None:
            return
        margin = self.battery_margin_fraction * uav_type.battery_wh
        if telemetry.battery_wh >= plan.tasks[0].energy_after_wh - margin:
            return
        if self._battery_flagged.get(telemetry.uav_id) == plan.epoch:
            return
        self._battery_flagged[telemetry.uav_id] = plan.epoch
        self.counters.battery_replans += 1
        self.events.emit(
            EventKind.FAULT,
            uav_id=telemetry.uav_id,
            detail=f"battery {telemetry.battery_wh:.1f} Wh below plan",
        )
        self.replan(f"{telemetry.uav_id} battery below plan")

    def on_fleet_changes(self, changes: list[tuple[str, Change]]) -> None:
        """A UAV was lost (after the grace) or came back: replan."""
        for uav_id, change in changes:
            kind = EventKind.UAV_LOST if change == Change.LOST else EventKind.UAV_BACK
            self.events.emit(kind, uav_id=uav_id)
            if change == Change.BACK:
                self.replanner.resend(uav_id)
        if changes:
            self.replan(", ".join(f"{u} {c}" for u, c in changes))

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
                self._transition(record, event, reason_text)
        return outcome.changed

    # -- records ---------------------------------------------------------------

    def _record(self, action_id: str) -> ActionRecord:
        record = self.store.action(action_id)
        if record is None:
            raise NotFound(f"no action {action_id!r}", field="action_id")
        return record

    def _live_record(self, action_id: str) -> ActionRecord:
        record = self._record(action_id)
        if record.state in TERMINAL:
            raise RequestError(
                f"action {action_id} is {record.state}",
                code="invalid_transition",
                field="action_id",
            )
        return record

    def _transition(self, record: ActionRecord, event: ActionEvent, reason: str) -> None:
        state = next_state(record.state, event)
        if state != record.state:
            self._save(
                msgspec.structs.replace(record, state=state, reason=reason), record.state, reason
            )
            self.events.emit(
                EventKind.ACTION_STATE,
                action_id=record.action_id,
                detail=f"{record.state}->{state}: {reason}",
            )

    def _save(self, record: ActionRecord, previous: ActionState, reason: str) -> None:
        now = self.clock()
        record = msgspec.structs.replace(record, updated_s=now)
        self.store.update_action(record, previous, now)
