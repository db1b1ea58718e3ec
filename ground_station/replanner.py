"""Runs the planner on the mission's current state and dispatches the result:
a new epoch for the plans that changed, stored before they are sent, and
the lifecycle events the new plan implies for each action."""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable

import msgspec

from ground_station import planner as pl
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.lifecycle import ActionEvent
from ground_station.planning import UavNow, build_problem, monitor_starts, same_work, to_tasks
from ground_station.store import Store
from proto.events import EventKind
from proto.mission import ActionRecord
from proto.plan import DeliverTask, GoHomeTask, MonitorTask, Plan
from proto.scenario import Scenario
from proto.telemetry import FlightState

log = logging.getLogger(__name__)

IMPOSSIBLE = frozenset({"unreachable_with_full_battery", "unknown_tool"})
"""Unplaced reasons that no change of fleet state can cure: the action fails."""

ON_PAD_M = 1.0
"""A landed UAV this close (horizontally) to a station is on its pad."""

AIRBORNE = frozenset({FlightState.FLYING, FlightState.TAKING_OFF, FlightState.LANDING})


@dataclasses.dataclass
class ReplanOutcome:
    """What one replan did."""

    epoch: int
    changed: list[Plan]
    action_events: dict[str, tuple[ActionEvent, str]]
    planning_time_s: float


@dataclasses.dataclass
class ReplanStats:
    """Count and latency of replans."""

    count: int = 0
    total_s: float = 0.0
    last_s: float = 0.0
    plans_sent: int = 0
    unchanged: int = 0  # replans that changed no UAV's plan (no event, no epoch)


class Replanner:
    """Keeps the current plan of every UAV and replaces it on demand."""

    def __init__(
        self,
        *,
        scenario: Scenario,
        store: Store,
        monitor: FleetMonitor,
        events: EventLog,
        send: Callable[[Plan], None],
        planner_options: pl.Options | None = None,
    ) -> None:
        self.scenario = scenario
        self.store = store
        self.monitor = monitor
        self.events = events
        self.send = send
        self.options = planner_options
        self.plans: dict[str, Plan] = store.latest_plans()
        self.stats = ReplanStats()
        self._resend: set[str] = set()
        # uav -> task id -> the epoch since which its plan holds that task
        # (restored conservatively as the stored plan's own epoch)
        self._since: dict[str, dict[str, int]] = {
            uav: {t.task_id: plan.epoch for t in plan.tasks} for uav, plan in self.plans.items()
        }

    def resend(self, uav_id: str) -> None:
        """Give ``uav_id`` a fresh plan (higher epoch) at the next replan."""
        self._resend.add(uav_id)

    def assigned_since(self, uav_id: str, task_id: str) -> int | None:
        """The epoch since which ``uav_id``'s plan holds ``task_id`` without a
        break (None if it does not hold it). Ids such as ``uav-1.home`` come
        back in later plans: an outcome reported under an older epoch is about
        an earlier task of that name."""
        return self._since.get(uav_id, {}).get(task_id)

    def _hold(self, plan: Plan) -> None:
        """``plan`` replaces the UAV's plan; tasks carried over keep their epoch."""
        before = self._since.get(plan.uav_id, {})
        self._since[plan.uav_id] = {
            t.task_id: before.get(t.task_id, plan.epoch) for t in plan.tasks
        }
        self.plans[plan.uav_id] = plan

    def finished(self, uav_id: str, task_id: str) -> None:
        """``task_id`` ended on ``uav_id``: drop it (and what preceded it) from
        the plan held for the UAV, as the agent dropped it from its queue. The
        epoch stays: the agent's queue and this plan still agree."""
        plan = self.plans.get(uav_id)
        if plan is None:
            return
        ids = [t.task_id for t in plan.tasks]
        if task_id in ids:
            rest = plan.tasks[ids.index(task_id) + 1 :]
            self.plans[uav_id] = msgspec.structs.replace(plan, tasks=rest)
            since = self._since.get(uav_id, {})
            self._since[uav_id] = {t.task_id: since[t.task_id] for t in rest if t.task_id in since}

    def replan(self, records: list[ActionRecord], now_s: float, reason: str) -> ReplanOutcome:
        """Plan ``records`` (the actions in force) from the fleet's state now."""
        site, fleet = self.scenario.site, self.scenario.fleet
        in_force = {r.action_id for r in records}
        starts = monitor_starts(self.plans.values())
        problem = build_problem(
            site, fleet, self._uavs_now(in_force), records, now_s, monitor_starts=starts
        )
        started = time.perf_counter()
        try:
            result = pl.plan(problem, self.options)
        except pl.PlanningProblemError as exc:  # fleet reports that contradict each other
            log.error("replan refused (%s): %s; plans kept", reason, exc)
            self.events.emit(EventKind.FAULT, detail=f"replan refused: {exc}; plans kept")
            return ReplanOutcome(self.store.counter("epoch"), [], {}, 0.0)
        elapsed = time.perf_counter() - started
        by_id = {r.action_id: r for r in records}
        new_tasks = {
            up.uav_id: self._drop_done_home(up.uav_id, to_tasks(up, site, fleet, by_id, now_s))
            for up in result.uavs
        }
        changed_ids = [
            u.id
            for u in fleet.uavs
            if u.id in self._resend or not same_work(new_tasks.get(u.id, []), self._tasks(u.id))
        ]
        epoch = self.store.counter("epoch")
        changed: list[Plan] = []
        if changed_ids:
            epoch = self.store.next_counter("epoch")
            changed = [
                Plan(uav_id=u, epoch=epoch, issued_s=now_s, tasks=new_tasks.get(u, []))
                for u in changed_ids
            ]
            self.store.save_plans(changed)
            for plan in changed:
                self._hold(plan)
                if self.monitor.available(plan.uav_id) or plan.uav_id in self._resend:
                    self.send(plan)
                    self.stats.plans_sent += 1
                self.events.emit(
                    EventKind.PLAN_CHANGED,
                    uav_id=plan.uav_id,
                    epoch=epoch,
                    detail=f"{len(plan.tasks)} tasks",
                )
            self._resend.difference_update(changed_ids)
        self.stats.count += 1
        self.stats.total_s += elapsed
        self.stats.last_s = elapsed
        if not changed:  # counted in /metrics, not worth an event
            self.stats.unchanged += 1
        else:
            self.events.emit(
                EventKind.REPLAN,
                epoch=epoch,
                detail=f"{reason}; {len(changed)} plan(s) changed in {elapsed * 1e3:.1f} ms",
            )
        return ReplanOutcome(epoch, changed, _action_events(records, new_tasks, result), elapsed)

    def _drop_done_home(self, uav_id: str, tasks: list) -> list:
        """A plan that only sends a UAV to the pad it already sits on asks
        nothing: it is empty (else the agent would "complete" it at once,
        over and over)."""
        telemetry = self.monitor.telemetry(uav_id)
        if len(tasks) != 1 or not isinstance(tasks[0], GoHomeTask) or telemetry is None:
            return tasks
        station = self.scenario.site.station(tasks[0].station_id)
        p = telemetry.position
        on_pad = (
            telemetry.flight_state == FlightState.LANDED
            and station is not None
            and math.hypot(p.x_m - station.position.x_m, p.y_m - station.position.y_m) <= ON_PAD_M
        )
        return [] if on_pad else tasks

    def _tasks(self, uav_id: str) -> list:
        plan = self.plans.get(uav_id)
        return plan.tasks if plan else []

    def _uavs_now(self, in_force: set[str]) -> list[UavNow]:
        site, fleet = self.scenario.site, self.scenario.fleet
        uavs = []
        for spec in fleet.uavs:
            telemetry = self.monitor.telemetry(spec.id)
            home = site.station(spec.home_station)
            capacity = fleet.type_of(spec.id).battery_wh
            uavs.append(
                UavNow(
                    uav_id=spec.id,
                    position=telemetry.position if telemetry else home.position,
                    energy_wh=min(capacity, telemetry.battery_wh) if telemetry else capacity,
                    available=self.monitor.available(spec.id),
                    airborne=bool(telemetry and telemetry.flight_state in AIRBORNE),
                    tool=telemetry.tool if telemetry else None,
                    running_action=self._running_action(spec.id, in_force),
                )
            )
        return uavs

    def _running_action(self, uav_id: str, in_force: set[str]) -> str | None:
        """The monitoring action in force the UAV is executing, or the delivery
        whose tool its telemetry says it holds, if any."""
        status, telemetry = self.monitor.status(uav_id), self.monitor.telemetry(uav_id)
        plan = self.plans.get(uav_id)
        if status is None or status.task_id is None or plan is None:
            return None
        for task in plan.tasks:
            if task.task_id != status.task_id or task.action_id not in in_force:
                continue
            holds_tool = telemetry is not None and telemetry.tool == getattr(task, "tool", None)
            if isinstance(task, MonitorTask) or (isinstance(task, DeliverTask) and holds_tool):
                return task.action_id
        return None


def _action_events(
    records: list[ActionRecord], tasks: dict[str, list], result: pl.Plan
) -> dict[str, tuple[ActionEvent, str]]:
    placed = {t.action_id for plan_tasks in tasks.values() for t in plan_tasks if t.action_id}
    unplaced: dict[str, list[pl.Unplaced]] = {}
    for item in result.unplaced:
        unplaced.setdefault(item.action_id, []).append(item)
    events: dict[str, tuple[ActionEvent, str]] = {}
    for record in records:
        missing = unplaced.get(record.action_id, [])
        reasons = ", ".join(sorted({m.reason for m in missing}))
        if record.action_id in placed:
            events[record.action_id] = (
                ActionEvent.PLACED,
                f"partly unplaced: {reasons}" if missing else "planned",
            )
        elif any(m.reason in IMPOSSIBLE for m in missing):
            events[record.action_id] = (ActionEvent.IMPOSSIBLE, reasons)
        else:
            events[record.action_id] = (ActionEvent.UNPLACED, reasons or "not planned")
    return events
