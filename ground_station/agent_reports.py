"""What agents report, applied to the mission: outcomes (fenced when stale,
credited as measured on board, deliveries confirmed by telemetry), status
(live monitoring progress) and telemetry (the tool carried, battery faults).

It decides which reports are replanning triggers (the paper's: an action
task finished or a task failed; not a finished wait, recharge or flight
home) and hands them to ``replan``.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable

import msgspec

from ground_station import progress
from ground_station.action_book import ActionBook
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.lifecycle import TERMINAL, ActionEvent
from ground_station.progress import apply_outcome
from ground_station.replanner import Replanner
from ground_station.store import StoreUnavailable
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState
from proto.plan import (
    DeliverTask,
    InspectTask,
    MonitorTask,
    PickTask,
    RechargeTask,
    Task,
    WaitTask,
)
from proto.rpc import UavOpState
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

ACTION_TASKS = (InspectTask, MonitorTask, PickTask, DeliverTask)
"""Tasks whose completion is a replanning trigger (the paper's "task
finished"). A finished wait, recharge or flight home changes nothing the
plan did not already expect, so it replans nothing, unless an action is
waiting for a UAV and the UAV is back on its pad or recharged (it may take
it); a finished wait never does (the UAV is as it was: chaos seed 15 replanned
on every wait it finished, and got the same wait again)."""

IDLE_MISMATCH_S = 5.0
"""Mission seconds an agent may report idle while its plan has tasks."""
MAX_TASK_FAILURES = 3
"""Failed attempts at one task that the ground station judged (a drop it could
not confirm; each resent after the first) before its action fails."""
MAX_RETRYABLE_FAILURES = 10
"""Failures for a passing reason at one task before its action fails anyway
(a guard against a reason that never passes)."""
EMERGENCY_PREFIX = "emergency:"
"""How an agent's reason for tasks dropped by its emergency protocol begins."""
ROUND_SLACK_S = 5.0
"""Monitoring segments planned to end within this of each other end one round."""
LIVE_PROGRESS_STEP = 0.02
"""A monitoring action's stored progress follows its flown share in steps of this."""
DROP_FRESH_S = 2.0
"""Telemetry this close in time to a drop's outcome tells where the drop was."""
DROP_RADIUS_M = 3.0
"""A tool released farther than this (horizontally) from the worker was not delivered."""


@dataclasses.dataclass
class Counters:
    """What the ground station counts of agents' reports (``/metrics``)."""

    outcomes: int = 0
    stale_outcomes: int = 0
    battery_replans: int = 0


class AgentReports:
    """Applies outcomes, status and telemetry; runs on the ground station's loop."""

    def __init__(
        self,
        *,
        scenario: Scenario,
        book: ActionBook,
        monitor: FleetMonitor,
        events: EventLog,
        replanner: Replanner,
        replan: Callable[[str], object],
        battery_margin_fraction: float = 0.1,
    ) -> None:
        self.scenario = scenario
        self.book = book
        self.monitor = monitor
        self.events = events
        self.replanner = replanner
        self.replan = replan
        self.battery_margin_fraction = battery_margin_fraction
        self.counters = Counters()
        self._battery_flagged: dict[str, int] = {}
        self._carried: dict[str, str] = {}  # the last tool each UAV's telemetry showed
        self._failures: dict[str, int] = {}  # failed outcomes per task id
        self._held: dict[str, list[TaskOutcome]] = {}  # from UAVs not back yet
        self._unsaved: list[TaskOutcome] = []  # the store could not take them yet
        self._idle_since: dict[str, float] = {}  # agent idle while its plan has tasks

    def on_outcome(self, outcome: TaskOutcome) -> None:
        """Apply an agent's outcome; stale ones are recorded only. An outcome
        from a UAV not yet back (a restarted ground station hears re-delivered
        outcomes before the token and telemetry) waits until it is back; one
        the store could not take waits for :meth:`retry_unsaved`."""
        if self.monitor.state(outcome.uav_id) == UavOpState.LOST:
            self._held.setdefault(outcome.uav_id, []).append(outcome)
            return
        self.counters.outcomes += 1
        self._apply_or_keep(outcome)

    def retry_unsaved(self) -> None:
        """Apply again, in order, the outcomes the store could not take."""
        unsaved, self._unsaved = self._unsaved, []
        for outcome in unsaved:
            self._apply_or_keep(outcome)

    def _apply_or_keep(self, outcome: TaskOutcome) -> None:
        try:
            self._apply(outcome)
        except StoreUnavailable as exc:  # its credit, the first write, was not kept
            self._unsaved.append(outcome)
            log.error(
                "outcome %s of %s waits for the store: %s", outcome.task_id, outcome.uav_id, exc
            )

    def _apply(self, outcome: TaskOutcome) -> None:
        plan = self.replanner.plans.get(outcome.uav_id)
        task = next((t for t in plan.tasks if t.task_id == outcome.task_id), None) if plan else None
        since = self.replanner.assigned_since(outcome.uav_id, outcome.task_id)
        if (
            task is None
            or plan is None
            or since is None
            or not since <= outcome.epoch <= plan.epoch
        ):
            if self._credit_superseded(outcome):
                return
            self.counters.stale_outcomes += 1
            self.events.emit(
                EventKind.FAULT,
                uav_id=outcome.uav_id,
                epoch=outcome.epoch,
                detail=f"stale outcome {outcome.task_id} {outcome.result}",
            )
            return
        judged = False
        if isinstance(task, DeliverTask) and outcome.result == OutcomeResult.COMPLETED:
            outcome, judged = self._confirm_drop(outcome, task), True
        completed = outcome.result == OutcomeResult.COMPLETED
        if task.action_id is not None:
            record = self.book.store.action(task.action_id)
            if record is not None and record.state not in TERMINAL:
                self._credit(record, task, outcome, f"{outcome.task_id} {outcome.result}")
        if isinstance(task, MonitorTask) and completed:
            self._announce_handover(outcome.uav_id, task)
        if isinstance(task, PickTask | DeliverTask) and completed:
            held = (outcome.tool or task.tool) if isinstance(task, PickTask) else None
            self.monitor.on_handled_tool(outcome.uav_id, held, outcome.stamp_s)
        self.replanner.finished(outcome.uav_id, outcome.task_id, completed)
        if outcome.result == OutcomeResult.FAILED and self._gave_up_safely(task, outcome, judged):
            return
        if not completed:
            # the agent dropped the task: if the replan gives it back unchanged
            # (same ids), it must still be sent, with a new epoch
            self.replanner.resend(outcome.uav_id)
        trigger = (
            not completed
            or isinstance(task, ACTION_TASKS)
            or (not isinstance(task, WaitTask) and self._waiting_for_a_uav())
        )
        if trigger and not self._round_ending(outcome.uav_id, task):
            self.replan(f"{outcome.uav_id} {outcome.task_id} {outcome.result}")

    def _credit_superseded(self, outcome: TaskOutcome) -> bool:
        """An outcome of work the plan of its epoch gave the UAV, reported
        after that plan was replaced (a ground station restarted while the
        UAV flew, and replanned before hearing it): the work was done, so its
        action is credited, idempotently (inspected waypoints, a tool picked
        or delivered; never monitoring seconds, which a loss voids). The
        current plan is left alone: an id such as ``uav-1.home`` may name
        other work in it."""
        if outcome.result != OutcomeResult.COMPLETED:
            return False
        then = self.book.store.plan_at(outcome.uav_id, outcome.epoch)
        task = next((t for t in then.tasks if t.task_id == outcome.task_id), None) if then else None
        if not isinstance(task, InspectTask | PickTask | DeliverTask) or task.action_id is None:
            return False
        record = self.book.store.action(task.action_id)
        if record is None or record.state in TERMINAL:
            return False
        if isinstance(task, DeliverTask):
            outcome = self._confirm_drop(outcome, task)
            if outcome.result != OutcomeResult.COMPLETED:
                return False
        why = f"{outcome.task_id} {outcome.result} (epoch {outcome.epoch}, reported late)"
        self._credit(record, task, outcome, why)
        self.replan(f"{outcome.uav_id} {outcome.task_id} reported late")
        return True

    def _credit(self, record: ActionRecord, task: Task, outcome: TaskOutcome, why: str) -> None:
        """Apply ``outcome`` of ``task`` to its action's ``record``."""
        updated, event = apply_outcome(record, task, outcome)
        self.book.update(record, updated, event, why)

    def release(self, uav_id: str) -> None:
        """``uav_id`` is back: apply the outcomes it sent meanwhile, in order."""
        for outcome in self._held.pop(uav_id, []):
            self.on_outcome(outcome)

    def _gave_up_safely(self, task: Task, outcome: TaskOutcome, judged: bool) -> bool:
        """:meth:`_gave_up`, after the credit was kept: a store failure now
        leaves the action in force (the next failure of the task fails it)."""
        try:
            return self._gave_up(task, outcome, judged)
        except StoreUnavailable as exc:
            log.error("failing the action of %s waits for the store: %s", task.task_id, exc)
            return False

    def _gave_up(self, task: Task, outcome: TaskOutcome, judged: bool) -> bool:
        """Whether the failure of ``task`` fails its action (then the work is
        replanned). A permanent failure from the agent (which already retried
        on board) does at once, with its reason and code; a retryable one (a
        passing reason, an emergency) only after ``MAX_RETRYABLE_FAILURES``;
        one the ground station ``judged`` (a drop it could not confirm) after
        ``MAX_TASK_FAILURES``."""
        if task.action_id is None or outcome.reason.startswith(EMERGENCY_PREFIX):
            return False
        self._failures[task.task_id] = count = self._failures.get(task.task_id, 0) + 1
        if judged:
            limit = MAX_TASK_FAILURES
        elif outcome.retryable:
            limit = MAX_RETRYABLE_FAILURES
        else:
            limit = 1
        if count < limit:
            return False
        record = self.book.store.action(task.action_id)
        if record is not None and record.state not in TERMINAL:
            code = f" [{outcome.reason_code}]" if outcome.reason_code else ""
            times = f" {count} times" if count > 1 else ""
            reason = f"{task.task_id} failed{times}{code}: {outcome.reason}"
            self.book.transition(record, ActionEvent.IMPOSSIBLE, reason)
        self.replan(f"{task.action_id} given up")
        return True

    def _waiting_for_a_uav(self) -> bool:
        """Whether an action in force is unplaced for now (no UAV could take it
        at the last replan): a UAV that landed or recharged may cure that."""
        return bool(self.book.store.actions([ActionState.ACCEPTED]))

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
        """A delivery counts as done only if the requested tool was carried (as
        the agent's gripper reports it, else as telemetry showed) and the UAV is
        at the worker; otherwise it is a failed drop."""
        seen = self._carried.pop(outcome.uav_id, None)
        carried = outcome.tool if outcome.tool is not None else seen
        problem = None
        if carried != task.tool:
            problem = f"{carried or 'no tool'} carried, not {task.tool}"
        elif (away := self._away_from_worker(outcome, task.worker_id)) is not None:
            problem = f"released {away:.1f} m from {task.worker_id}"
        if problem is None:
            return outcome
        self.events.emit(
            EventKind.FAULT, uav_id=outcome.uav_id, detail=f"delivery not confirmed: {problem}"
        )
        return msgspec.structs.replace(outcome, result=OutcomeResult.FAILED, reason=problem)

    def _away_from_worker(self, outcome: TaskOutcome, worker_id: str) -> float | None:
        """How far (horizontally) the UAV is from a worker who stands still,
        if farther than ``DROP_RADIUS_M``; None when close or not checkable
        (no telemetry from the moment of the drop: a re-delivered outcome)."""
        telemetry = self.monitor.telemetry(outcome.uav_id)
        worker = self.scenario.site.worker(worker_id)
        if telemetry is None or worker is None or worker.path:
            return None
        if abs(telemetry.stamp_s - outcome.stamp_s) > DROP_FRESH_S:
            return None
        p, w = telemetry.position, worker.position
        away = ((p.x_m - w.x_m) ** 2 + (p.y_m - w.y_m) ** 2) ** 0.5
        return away if away > DROP_RADIUS_M else None

    def on_status(self, status: AgentStatus) -> None:
        """Show a monitoring action's progress while it is flown (outcomes
        only come at the end of a segment): in progress, and its share in %;
        and notice an agent idle on the epoch of a plan that still has work."""
        self._check_idle(status)
        task = self._monitoring(status)
        if task is None or task.action_id is None:
            return
        record = self.book.store.action(task.action_id)
        if record is None or record.state in TERMINAL:
            return
        statuses = [self.monitor.status(uav.id) for uav in self.scenario.fleet.uavs]
        flying = [(self._monitoring(s), s.progress) for s in statuses if s is not None]
        running = [(t, p) for t, p in flying if t is not None and t.action_id == task.action_id]
        live = progress.live_monitor_progress(record, running)
        if record.state != ActionState.IN_PROGRESS:
            self.book.transition(record, ActionEvent.STARTED, f"{task.task_id} on station")
            record = self.book.record(record.action_id)
        if live - record.progress >= LIVE_PROGRESS_STEP:
            self.book.save(msgspec.structs.replace(record, progress=live), record.state, "flying")

    def _check_idle(self, status: AgentStatus) -> None:
        """An agent idle with an empty queue on the epoch of a plan that still
        holds tasks (an outcome lost in an outage, a plan it never got) for
        ``IDLE_MISMATCH_S``: send it its work again, with a new epoch."""
        plan = self.replanner.plans.get(status.uav_id)
        idle = status.state == AgentState.IDLE and status.queue_length == 0
        if plan is None or not plan.tasks or not idle or status.epoch != plan.epoch:
            self._idle_since.pop(status.uav_id, None)
            return
        since = self._idle_since.setdefault(status.uav_id, status.stamp_s)
        if status.stamp_s - since >= IDLE_MISMATCH_S:
            self._idle_since.pop(status.uav_id, None)
            self.replanner.resend(status.uav_id)
            self.replan(f"{status.uav_id} idle without its plan's tasks")

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
