"""The mission manager: actions in, plans out.

It validates and stores operator requests (idempotent on the client's
request id, durable before the reply), hands agents' reports to
:class:`~ground_station.agent_reports.AgentReports`, and replans on every
trigger of the paper, sending a plan with a new epoch to each UAV whose work
changed. Requests never wait for planning: they reply once the change is
committed (a new action is ``accepted``) and trigger the planning worker
(:class:`~ground_station.plan_worker.PlanWorker`), which moves actions to
``planned`` or ``failed``. It does no I/O of its own besides the store:
plans and events leave through the callables given.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TypedDict

import msgspec

from ground_station import inventory
from ground_station.action_book import ActionBook
from ground_station.agent_reports import AgentReports
from ground_station.event_log import EventLog
from ground_station.fleet_events import TOLD_ONLY, fleet_event
from ground_station.fleet_monitor import Change, FleetMonitor
from ground_station.fleet_state import AIRBORNE
from ground_station.lifecycle import TERMINAL, TRANSITIONS, ActionEvent
from ground_station.monitor_bearings import as_requested, moved_off, with_bearing
from ground_station.paging import fitting, page
from ground_station.plan_worker import PlanWorker
from ground_station.replan_jobs import Computed, ReplanJob, ReplanOutcome
from ground_station.replanner import Replanner
from ground_station.store import Store, StoreUnavailable
from ground_station.validation import validate
from proto.errors import Conflict, InvalidAction, NotFound
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState, DeliverAction, MonitorAction
from proto.plan import MonitorTask, Plan, WaitTask
from proto.rpc import (
    ActionList,
    CancelAction,
    Command,
    ControlUav,
    FleetReply,
    GetHistory,
    HistoryReply,
    ListActions,
    ModifyAction,
    PlansReply,
    SubmitAction,
)
from proto.scenario import Scenario

log = logging.getLogger(__name__)


RETRY_UNPLACED_S = 30.0
"""Mission seconds between retries of actions that no UAV could take yet."""


class PlanQuality(TypedDict):
    """The live plan's quality, the fields of a ``PlansReply`` beside the plans."""

    objective_s: float | None
    improved_ago_s: float | None
    gap_to_best: float | None


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
        improve: bool = True,
        improve_delay_s: float = 0.5,
    ) -> None:
        self.scenario = scenario
        self.store = store
        self.monitor = monitor
        self.events = events
        self.replanner = replanner
        self.clock = clock
        self.book = ActionBook(store, events, clock)
        self._retried_s = clock()
        self._unvoided: list[str] = []  # lost UAVs whose segments the store has yet to void
        self._store_said: str | None = None  # the store failure last told the operator
        self.worker = PlanWorker(self, improve=improve, improve_delay_s=improve_delay_s)
        self.reports = AgentReports(
            scenario=scenario,
            book=self.book,
            monitor=monitor,
            events=events,
            replanner=replanner,
            replan=self.request_replan,
            battery_margin_fraction=battery_margin_fraction,
        )

    # -- requests (the gs's dispatch table, GroundStation.answers, calls these) --

    def list_actions(self, request: ListActions) -> ActionList:
        """Actions in ``request.states`` (all if none), a page at a time."""
        records = self.store.actions(request.states)
        shown, more = page(records, lambda r: r.action_id, request.cursor, request.limit)
        return ActionList(records=shown, next_cursor=more)

    def history(self, request: GetHistory) -> HistoryReply:
        """Events after ``request.after_seq``, as many as fit one reply."""
        events = fitting(self.events.after(request.after_seq, request.limit))
        return HistoryReply(events=events, last_seq=self.events.last_seq)

    def plans(self, uav_id: str | None = None) -> PlansReply:
        """The current plans (of ``uav_id`` only, if given), with the live
        plan's quality: what operators and an agent's resync query read."""
        plans = self.replanner.plans
        chosen = [plans[uav_id]] if uav_id in plans else [] if uav_id else plans.values()
        return PlansReply(plans=list(chosen), **self.plan_quality())

    def fleet(self) -> FleetReply:
        """Every UAV's state, with the operator's command in force."""
        control = self.replanner.control
        uavs = [
            msgspec.structs.replace(u, control=control.command(u.uav_id))
            for u in self.monitor.snapshot(self.replanner.plans)
        ]
        return FleetReply(uavs=uavs)

    def control(self, request: ControlUav) -> FleetReply:
        """An operator's command for one UAV (or all): its work is replanned
        to the others at once, and it gets the command's task. Answers the
        fleet as it is now."""
        if request.uav_id is not None and not self.monitor.known(request.uav_id):
            raise NotFound(f"no UAV {request.uav_id!r} in the fleet", field="uav_id")
        targets = [request.uav_id] if request.uav_id else [u.id for u in self.scenario.fleet.uavs]
        control, now = self.replanner.control, self.clock()
        for uav_id in targets:
            if request.command is not Command.RESUME and uav_id not in control.controlled:
                self._void_segments(uav_id)  # a held UAV keeps its slot: others get another
            control.order(uav_id, request.command, now)
            self.replanner.resend(uav_id)
            self.events.emit(
                EventKind.UAV_CONTROL, uav_id=uav_id, detail=f"operator: {request.command}"
            )
        self.request_replan(f"operator: {request.command} {request.uav_id or 'all'}", stale=True)
        return self.fleet()

    def plan_quality(self) -> PlanQuality:
        """The live plan's objective (seconds: weight-averaged completion +
        makespan), how long ago an improvement was adopted, and its gap to
        the best plan seen for the same state."""
        rp = self.replanner
        objective = rp.objective[1] if rp.objective else None
        best = rp.best_objective[1] if rp.best_objective else None
        gap = (objective - best) / best if objective is not None and best else None
        ago = self.clock() - rp.improved_s if rp.improved_s is not None else None
        return PlanQuality(objective_s=objective, improved_ago_s=ago, gap_to_best=gap)

    def submit(self, request: SubmitAction) -> ActionRecord:
        """Accept an action: validated, stored durably, then planned (later)."""
        existing = self.store.action_by_request(request.request_id)
        action = request.action
        if existing is not None:
            stored = existing.action
            if isinstance(stored, MonitorAction) and isinstance(action, MonitorAction):
                stored = as_requested(stored, action)
            if stored != action:
                raise Conflict("request_id already used for another action", field="request_id")
            if request.action_id not in (None, existing.action_id):
                raise Conflict(
                    f"request_id already used for action {existing.action_id!r}",
                    field="action_id",
                )
            return existing
        validate(action, self.scenario.site, self.scenario.fleet)
        if isinstance(action, DeliverAction):
            inventory.reserve(self.scenario.site, self.store.actions(), action)
        if isinstance(action, MonitorAction):
            action = with_bearing(action, self.in_force(), self.scenario.site)
        action_id = request.action_id or f"act-{self.store.next_counter('action'):05d}"
        if self.store.action(action_id) is not None:
            raise Conflict(f"action id {action_id!r} exists", field="action_id")
        now = self.clock()
        record = ActionRecord(
            action_id=action_id,
            action=action,
            state=ActionState.ACCEPTED,
            created_s=now,
            updated_s=now,
            request_id=request.request_id,
        )
        self.store.insert_action(record, now)
        self.events.emit(
            EventKind.ACTION_ACCEPTED, action_id=action_id, detail=type(action).__name__
        )
        self.request_replan(f"action {action_id} added")
        return self.book.record(action_id)

    def modify(self, request: ModifyAction) -> ActionRecord:
        """Change an action's priority and/or parameters, then replan."""
        record = self.book.live_record(request.action_id)
        action = request.action or record.action
        if type(action) is not type(record.action):
            raise InvalidAction("cannot change an action's kind", field="action.type")
        if request.priority is not None:
            action = msgspec.structs.replace(action, priority=request.priority)
        validate(action, self.scenario.site, self.scenario.fleet)
        if isinstance(action, DeliverAction):
            others = [r for r in self.store.actions() if r.action_id != record.action_id]
            inventory.reserve(self.scenario.site, others, action)
        if isinstance(action, MonitorAction) and action.bearing_deg is None:
            assert isinstance(record.action, MonitorAction)  # same kind, checked above
            action = msgspec.structs.replace(action, bearing_deg=record.action.bearing_deg)
        self.book.save(msgspec.structs.replace(record, action=action), record.state, "modified")
        self.events.emit(EventKind.ACTION_CHANGED, action_id=record.action_id)
        self.request_replan(f"action {record.action_id} changed")
        return self.book.record(record.action_id)

    def cancel(self, request: CancelAction) -> ActionRecord:
        """Cancel an action (idempotent), then replan."""
        record = self.book.record(request.action_id)
        if record.state == ActionState.CANCELLED:
            return record
        self.book.transition(record, ActionEvent.CANCEL, "cancelled by operator")
        self.events.emit(EventKind.ACTION_CANCELLED, action_id=record.action_id)
        self.request_replan(f"action {record.action_id} cancelled", stale=True)
        return self.book.record(record.action_id)

    # -- agents ----------------------------------------------------------------

    def on_fleet_changes(self, changes: list[tuple[str, Change]]) -> None:
        """A UAV was lost (after the grace), crashed, failed, is not ready, or
        came back: replan. One fell silent or was heard again: only told."""
        for uav_id, change in changes:
            kind, detail = fleet_event(self.monitor, uav_id, change)
            self.events.emit(kind, uav_id=uav_id, detail=detail)
        changes = [(u, c) for u, c in changes if c not in TOLD_ONLY]
        for uav_id, change in changes:
            if change == Change.BACK:
                self.replanner.resend(uav_id)
            else:
                self._unvoided.append(uav_id)
        self._void_pending()
        if changes:
            self.request_replan(", ".join(f"{u} {c}" for u, c in changes), stale=True)
        for uav_id, change in changes:
            if change == Change.BACK:
                self.reports.release(uav_id)

    def retry_unsaved(self) -> None:
        """What the store could not take, tried again (each watchdog step):
        events, agents' outcomes, the voiding of a lost UAV's segments. The
        operator is told when the store starts failing and when it is back."""
        self.events.flush()
        if self.store.failing != self._store_said:
            self._store_said = self.store.failing
            detail = (
                f"the store cannot write ({self._store_said}): new actions are refused (503) "
                "and reports wait until it can"
                if self._store_said
                else "the store writes again"
            )
            self.events.emit(EventKind.FAULT, detail=detail)
        self.reports.retry_unsaved()
        if self._unvoided:
            self._void_pending()
            if not self._unvoided:
                self.request_replan("the store writes again")

    def _void_pending(self) -> None:
        while self._unvoided:
            try:
                self._void_segments(self._unvoided[0])
            except StoreUnavailable as exc:
                log.error("voiding %s's segments waits for the store: %s", self._unvoided[0], exc)
                return
            self._unvoided.pop(0)

    def _void_segments(self, uav_id: str) -> None:
        """A lost UAV's monitoring assignments end with the loss: its later
        segments get new ids, so its late report of the old ones is stale.
        Lost in the air, it may hover on at the slot it held or was waiting
        for (a hung agent's autopilot holds its last target): that slot is
        moved clear of it (:func:`monitor_bearings.moved_off`)."""
        plan = self.replanner.plans.get(uav_id)
        watched = {t.action_id for t in plan.tasks if isinstance(t, MonitorTask)} if plan else set()
        held = self._held_slot(uav_id, plan)
        for action_id in sorted(a for a in watched if a is not None):
            record = self.store.action(action_id)
            if not self.book.in_force(record):
                continue
            assert record is not None
            segments = {**record.segments, uav_id: record.segments.get(uav_id, 0) + 1}
            updated = msgspec.structs.replace(record, segments=segments)
            if held is not None and held.action_id == action_id:
                updated = moved_off(updated, held.slot, self.in_force(), self.scenario.site)
            self.book.save(updated, record.state, "UAV lost")

    def _held_slot(self, uav_id: str, plan: Plan | None) -> MonitorTask | None:
        """The monitoring task ``uav_id`` was flying (or waiting in the air
        for) when it was last heard, if it is in the air."""
        telemetry, status = self.monitor.telemetry(uav_id), self.monitor.status(uav_id)
        if plan is None or status is None or telemetry is None:
            return None
        if telemetry.flight_state not in AIRBORNE:
            return None
        ids = [t.task_id for t in plan.tasks]
        if status.task_id not in ids:
            return None
        at = ids.index(status.task_id)
        for task in plan.tasks[at : at + 2]:  # the task, or the one a wait holds for
            if isinstance(task, MonitorTask):
                return task
            if not isinstance(task, WaitTask):
                return None
        return None

    def retry_unplaced(self) -> None:
        """Replan every ``RETRY_UNPLACED_S`` mission seconds while an action
        waits for a UAV (accepted, or in progress with a part the plan left
        out): batteries filling on pads are no event, yet they make the work
        placeable (a replan that places nothing changes nothing)."""
        now = self.clock()
        if now - self._retried_s < RETRY_UNPLACED_S:
            return
        self._retried_s = now
        if self.replanner.waiting or self.store.actions([ActionState.ACCEPTED]):
            self.request_replan("retry of actions waiting for a UAV")

    # -- planning --------------------------------------------------------------

    def request_replan(self, reason: str, *, stale: bool = False) -> None:
        """Trigger a replan (returns at once; the worker plans). ``stale``:
        the change makes a replan in flight outdated (it is run again)."""
        if stale:
            self.replanner.bump()
        self.worker.trigger(reason)

    def replan(self, reason: str) -> list[Plan]:
        """Plan the actions in force now, synchronously; returns the plans
        that changed."""
        changed = self.finish_replan(self.replanner.compute(self.prepare_replan(reason)))
        return changed or []

    def in_force(self) -> list[ActionRecord]:
        return self.store.actions(
            [ActionState.ACCEPTED, ActionState.PLANNED, ActionState.IN_PROGRESS]
        )

    def prepare_replan(self, reason: str) -> ReplanJob:
        """A replan's inputs, now (on the loop)."""
        return self.replanner.prepare(self.in_force(), self.clock(), reason)

    def prepare_improvement(self) -> ReplanJob:
        """An improvement attempt's inputs, now (on the loop)."""
        return self.replanner.prepare_improvement(self.in_force(), self.clock())

    def finish_replan(self, computed: Computed) -> list[Plan] | None:
        """Commit a computed replan (on the loop) and move its actions on;
        the plans that changed, or None if it was dropped as outdated."""
        outcome = self.replanner.commit(computed)
        if outcome is None:
            return None
        self._apply(outcome, computed.job.records)
        return outcome.changed

    def finish_improvement(self, computed: Computed | None, interrupted: bool = False) -> None:
        """Adopt an improvement if the hysteresis lets it through (on the loop)."""
        outcome = self.replanner.adopt(computed, interrupted)
        if outcome is not None and computed is not None:
            self._apply(outcome, computed.job.records)

    def _apply(self, outcome: ReplanOutcome, records: list[ActionRecord]) -> None:
        """Move each action on as the plan says; an action whose state the
        event leaves alone (as of the replan's inputs) is not read again,
        unless the plan leaves it waiting (the record says why)."""
        before = {r.action_id: (r.state, r.reason) for r in records}
        for action_id, (event, reason_text) in outcome.action_events.items():
            state, reason = before.get(action_id, (None, ""))
            kept = state is not None and TRANSITIONS.get((state, event)) == state
            if kept and (event is not ActionEvent.UNPLACED or reason == reason_text):
                continue
            record = self.store.action(action_id)
            if record is not None and record.state not in TERMINAL:
                self.book.transition(record, event, reason_text)
