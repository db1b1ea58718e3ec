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

from ground_station import inventory, progress
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import Change, FleetMonitor
from ground_station.lifecycle import TERMINAL, ActionEvent, next_state
from ground_station.progress import apply_outcome
from ground_station.replanner import Replanner
from ground_station.store import Store
from ground_station.validation import validate
from proto.errors import RequestError
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState, DeliverAction
from proto.plan import (
    DeliverTask,
    InspectTask,
    MonitorTask,
    PickTask,
    Plan,
    RechargeTask,
    Task,
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
from proto.telemetry import (
    AgentState,
    AgentStatus,
    FlightState,
    OutcomeResult,
    TaskOutcome,
    Telemetry,
)

log = logging.getLogger(__name__)

ROUND_SLACK_S = 5.0
"""Monitoring segments planned to end within this of each other end one round."""
LIVE_PROGRESS_STEP = 0.02
"""A monitoring action's stored progress follows its flown share in steps of this."""
DROP_RADIUS_M = 3.0
"""A tool released farther than this (horizontally) from the worker was not delivered."""

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

ACTION_TASKS = (InspectTask, MonitorTask, PickTask, DeliverTask)
"""Tasks whose completion is a replanning trigger (the paper's "task
finished"). A finished wait, recharge or flight home changes nothing the
plan did not already expect, so it replans nothing, unless an action is
waiting for a UAV (then a UAV back on its pad or recharged may take it)."""


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
        self._carried: dict[str, str] = {}  # the last tool each UAV's telemetry showed

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
        if isinstance(action, DeliverAction):
            others = [r for r in self.store.actions() if r.action_id != record.action_id]
            inventory.reserve(self.scenario.site, others, action)
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
        if isinstance(task, DeliverTask) and outcome.result == OutcomeResult.COMPLETED:
            outcome = self._confirm_drop(outcome, task)
        if task.action_id is not None:
            record = self.store.action(task.action_id)
            if record is not None and record.state not in TERMINAL:
                updated, event = apply_outcome(record, task, outcome)
                self._save(updated, record.state, f"{outcome.task_id} {outcome.result}")
                if event is not None:
                    self._transition(updated, event, f"{outcome.task_id} {outcome.result}")
        if isinstance(task, MonitorTask) and outcome.result == OutcomeResult.COMPLETED:
            self._announce_handover(outcome.uav_id, task)
        self.replanner.finished(outcome.uav_id, outcome.task_id)
        trigger = (
            outcome.result != OutcomeResult.COMPLETED
            or isinstance(task, ACTION_TASKS)
            or self._waiting_for_a_uav()
        )
        if trigger and not self._round_ending(outcome.uav_id, task):
            self.replan(f"{outcome.uav_id} {outcome.task_id} {outcome.result}")

    def _waiting_for_a_uav(self) -> bool:
        """Whether an action in force is unplaced for now (no UAV could take it
        at the last replan): a UAV that landed or recharged may cure that."""
        return bool(self.store.actions([ActionState.ACCEPTED]))

    def _round_ending(self, uav_id: str, task: Task) -> bool:
        """Whether ``task`` is one of a monitoring action's k segments that end
        together, and another of them has yet to report: the last one replans
        (one replan per round, from complete accounting)."""
        if not isinstance(task, MonitorTask) or task.end_s <= 0:
            return False
        for other_uav, plan in self.replanner.plans.items():
            if other_uav == uav_id or not self.monitor.available(other_uav):
                continue
            for other in plan.tasks:
                if (
                    isinstance(other, MonitorTask)
                    and other.action_id == task.action_id
                    and abs(other.end_s - task.end_s) <= ROUND_SLACK_S
                ):
                    return True
        return False

    def _announce_handover(self, leaving: str, task: MonitorTask) -> None:
        """A segment ended: if another UAV holds the same slot next, say so."""
        for uav_id, plan in self.replanner.plans.items():
            if uav_id == leaving:
                continue
            for other in plan.tasks:
                same_slot = isinstance(other, MonitorTask) and other.slot == task.slot
                if same_slot and other.action_id == task.action_id:
                    self.events.emit(
                        EventKind.HANDOVER,
                        action_id=task.action_id,
                        uav_id=uav_id,
                        detail=f"slot {task.slot} of {task.worker_id}: {leaving} -> {uav_id}",
                    )
                    return

    def _confirm_drop(self, outcome: TaskOutcome, task: DeliverTask) -> TaskOutcome:
        """A delivery counts as done only if telemetry showed the requested tool
        carried and the UAV is at the worker; otherwise it is a failed drop."""
        carried = self._carried.pop(outcome.uav_id, None)
        problem = None
        if carried != task.tool:
            problem = f"telemetry showed {carried or 'no tool'} carried, not {task.tool}"
        elif (away := self._away_from_worker(outcome.uav_id, task.worker_id)) is not None:
            problem = f"released {away:.1f} m from {task.worker_id}"
        if problem is None:
            return outcome
        self.events.emit(
            EventKind.FAULT, uav_id=outcome.uav_id, detail=f"delivery not confirmed: {problem}"
        )
        return msgspec.structs.replace(outcome, result=OutcomeResult.FAILED, reason=problem)

    def _away_from_worker(self, uav_id: str, worker_id: str) -> float | None:
        """How far (horizontally) the UAV is from a worker who stands still,
        if farther than ``DROP_RADIUS_M``; None when close or not checkable."""
        telemetry = self.monitor.telemetry(uav_id)
        worker = self.scenario.site.worker(worker_id)
        if telemetry is None or worker is None or worker.path:
            return None
        p, w = telemetry.position, worker.position
        away = ((p.x_m - w.x_m) ** 2 + (p.y_m - w.y_m) ** 2) ** 0.5
        return away if away > DROP_RADIUS_M else None

    def on_status(self, status: AgentStatus) -> None:
        """Show a monitoring action's progress while it is flown (outcomes
        only come at the end of a segment): in progress, and its share in %."""
        task = self._monitoring(status)
        if task is None or task.action_id is None:
            return
        record = self.store.action(task.action_id)
        if record is None or record.state in TERMINAL:
            return
        running = []
        for uav in self.scenario.fleet.uavs:
            other = self.monitor.status(uav.id)
            flown = self._monitoring(other) if other is not None else None
            if flown is not None and flown.action_id == task.action_id:
                running.append((flown, other.progress))
        live = progress.live_monitor_progress(record, running)
        if record.state != ActionState.IN_PROGRESS:
            self._transition(record, ActionEvent.STARTED, f"{task.task_id} on station")
            record = self._record(record.action_id)
        if live - record.progress >= LIVE_PROGRESS_STEP:
            self._save(msgspec.structs.replace(record, progress=live), record.state, "flying")

    def _monitoring(self, status: AgentStatus) -> MonitorTask | None:
        """The monitoring task ``status`` says is being flown, if any."""
        plan = self.replanner.plans.get(status.uav_id)
        if plan is None or status.state != AgentState.BUSY or status.progress <= 0:
            return None
        task = next((t for t in plan.tasks if t.task_id == status.task_id), None)
        return task if isinstance(task, MonitorTask) else None

    def on_telemetry(self, telemetry: Telemetry) -> None:
        """Note the tool carried; replan once per plan if the battery of a UAV
        in flight is below the plan's estimate for its current task by a margin."""
        if telemetry.tool is not None:
            self._carried[telemetry.uav_id] = telemetry.tool
        plan = self.replanner.plans.get(telemetry.uav_id)
        uav_type = self.scenario.fleet.type_of(telemetry.uav_id)
        if not plan or not plan.tasks or uav_type is None:
            return
        if isinstance(plan.tasks[0], RechargeTask) or telemetry.flight_state == FlightState.LANDED:
            return  # charging, or drawing nothing on a pad: not a battery fault
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
        """A UAV was lost (after the grace), crashed, or came back: replan."""
        for uav_id, change in changes:
            self.events.emit(FLEET_EVENTS[change], uav_id=uav_id, detail=FLEET_TEXT[change])
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
            if state == ActionState.FAILED:
                self.events.emit(EventKind.ACTION_FAILED, action_id=record.action_id, detail=reason)

    def _save(self, record: ActionRecord, previous: ActionState, reason: str) -> None:
        now = self.clock()
        record = msgspec.structs.replace(record, updated_s=now)
        self.store.update_action(record, previous, now)
