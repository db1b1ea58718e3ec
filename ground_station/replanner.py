"""Runs the planner on the mission's current state and dispatches the result:
a new epoch for the plans that changed, stored before they are sent, and
the lifecycle events the new plan implies for each action. Every replan and
every improvement goes through one incremental planner session
(:mod:`ground_station.live_plan`); the planning worker
(:mod:`ground_station.plan_worker`) runs them off the request path."""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable

import msgspec

from ground_station import planner as pl
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.fleet_state import AIRBORNE, Docks, drop_done_home, flying_segments, uavs_now
from ground_station.live_plan import (
    LivePlan,
    Objective,
    accept,
    better_by,
    freeze_broken,
    frozen_parts,
    frozen_tasks,
)
from ground_station.operator_control import OperatorControl
from ground_station.placement import placement_events
from ground_station.planning import (
    build_problem,
    capacity_wh,
    monitor_starts,
    name_reliefs,
    same_work,
)
from ground_station.replan_jobs import (
    Computed,
    ImproveSettings,
    ReplanJob,
    ReplanOutcome,
    ReplanStats,
)
from ground_station.store import Store, StoreUnavailable
from ground_station.wire_tasks import to_tasks
from proto.events import EventKind
from proto.mission import ActionRecord
from proto.plan import Plan
from proto.scenario import Scenario

log = logging.getLogger(__name__)

CONVERGED = 0.001
"""An improvement attempt that gains less than this fraction over the last
one has converged: no more attempts on this state."""


class Replanner:
    """Keeps the current plan of every UAV and replaces it on demand.

    Every replan goes through the one incremental session of
    :class:`~ground_station.live_plan.LivePlan`; ``replan`` does a whole
    replan at once, ``prepare`` / ``compute`` / ``commit`` split it so that
    ``compute`` (pure planning) runs off the loop."""

    def __init__(
        self,
        *,
        scenario: Scenario,
        store: Store,
        monitor: FleetMonitor,
        events: EventLog,
        send: Callable[[Plan], None],
        planner_options: pl.Options | None = None,
        improve: ImproveSettings | None = None,
        session_window_s: float = 10.0,
    ) -> None:
        self.scenario = scenario
        self.control = OperatorControl(scenario)  # UAVs an operator took out of the plan
        self.docks = Docks(scenario)
        self.store = store
        self.monitor = monitor
        self.events = events
        self.send = send
        self.options = planner_options
        self.improve_settings = improve or ImproveSettings()
        self.live = LivePlan(planner_options, session_window_s)
        self.plans: dict[str, Plan] = store.latest_plans()
        self.stats = ReplanStats()
        self.version = 0  # bumped by changes that make a replan in flight stale
        self.waiting: set[str] = set()  # actions the adopted plan leaves (partly) unplaced
        self.objective: Objective | None = None  # of the live plan
        self.best_objective: Objective | None = None  # best seen for this state
        self.improved_s: float | None = None  # mission s of the last adopted improvement
        self._attempts = 0  # improvement attempts on the current state
        self._restart = False  # the next attempt starts from a fresh construction
        self._resend: set[str] = set()
        # uav -> task id -> the epoch since which its plan holds that task
        # (restored conservatively as the stored plan's own epoch)
        self._since: dict[str, dict[str, int]] = {
            uav: {t.task_id: plan.epoch for t in plan.tasks} for uav, plan in self.plans.items()
        }

    def resend(self, uav_id: str) -> None:
        """Give ``uav_id`` a fresh plan (higher epoch) at the next replan."""
        self._resend.add(uav_id)

    def bump(self) -> None:
        """Something changed that a replan in flight did not see: its result
        is dropped (and the replan run again)."""
        self.version += 1

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

    def finished(self, uav_id: str, task_id: str, completed: bool = False) -> None:
        """``task_id`` ended on ``uav_id``: drop it (and what preceded it) from
        the plan held for the UAV, as the agent dropped it from its queue. The
        epoch stays: the agent's queue and this plan still agree."""
        self.control.finished(uav_id, task_id)
        plan = self.plans.get(uav_id)
        if plan is None:
            return
        ids = [t.task_id for t in plan.tasks]
        if task_id in ids:
            at = ids.index(task_id)
            rest = plan.tasks[at + 1 :]
            self.plans[uav_id] = msgspec.structs.replace(plan, tasks=rest)
            since = self._since.get(uav_id, {})
            self._since[uav_id] = {t.task_id: since[t.task_id] for t in rest if t.task_id in since}
            self.live.finished(uav_id, plan.tasks[at], completed)
            self.bump()

    # -- replans -----------------------------------------------------------------

    def replan(self, records: list[ActionRecord], now_s: float, reason: str) -> ReplanOutcome:
        """Plan ``records`` (the actions in force) from the fleet's state now."""
        outcome = self.commit(self.compute(self.prepare(records, now_s, reason)))
        assert outcome is not None  # nothing can change in between
        return outcome

    def prepare(self, records: list[ActionRecord], now_s: float, reason: str) -> ReplanJob:
        """The inputs of a replan, as the mission stands (on the loop)."""
        in_force = {r.action_id for r in records}
        return ReplanJob(
            records=list(records),
            now_s=now_s,
            reason=reason,
            uavs=uavs_now(
                self.scenario,
                self.docks,
                self.monitor,
                self.plans,
                in_force,
                self.control.controlled,
            ),
            starts=monitor_starts(self.plans.values()),
            version=self.version,
            flying=flying_segments(self.monitor, self.plans, in_force),
        )

    def compute(self, job: ReplanJob) -> Computed:
        """Plan ``job`` on the live session (pure: any thread, one at a time)."""
        site, fleet = self.scenario.site, self.scenario.fleet
        capacities = {u.id: capacity_wh(fleet, u.id) for u in fleet.uavs}

        def build(base_s: float) -> pl.Problem:
            return build_problem(
                site,
                fleet,
                job.uavs,
                job.records,
                base_s,
                monitor_starts=job.starts,
                flying=job.flying.values(),
            )

        started = time.perf_counter()
        try:
            planned = self.live.replan(build, job.now_s, capacities)
        except pl.PlanningProblemError as exc:  # fleet reports that contradict each other
            self.live.invalidate("the last problem was refused")
            return Computed(job, {}, error=str(exc))
        except Exception:
            self.live.invalidate("the last replan failed")
            raise
        elapsed = time.perf_counter() - started
        return Computed(
            job,
            self._wire(planned.plan, job, planned.base_s),
            result=planned.plan,
            elapsed_s=elapsed,
            incremental=planned.incremental,
            rebuilt_for=planned.rebuilt_for,
        )

    def _wire(self, result: pl.Solution, job: ReplanJob, base_s: float) -> dict:
        site, fleet = self.scenario.site, self.scenario.fleet
        by_id = {r.action_id: r for r in job.records}
        return name_reliefs(
            {up.uav_id: to_tasks(up, site, fleet, by_id, base_s, job.flying) for up in result.uavs}
        )

    def commit(self, computed: Computed) -> ReplanOutcome | None:
        """Adopt a computed plan (on the loop): a new epoch for the UAVs whose
        work changed, stored, then sent. None if the mission changed since
        ``prepare`` in a way the result did not see: it is dropped."""
        job = computed.job
        if job.version != self.version:  # the session goes on: the rerun diffs from it
            self.stats.dropped += 1
            return None
        if computed.result is None:
            log.error("replan refused (%s): %s; plans kept", job.reason, computed.error)
            detail = f"replan refused: {computed.error}; plans kept"
            self.events.emit(EventKind.FAULT, detail=detail)
            return ReplanOutcome(self.store.counter("epoch"), [], {}, 0.0)
        result, elapsed = computed.result, computed.elapsed_s
        ordered = {u: order.tasks for u, order in self.control.orders.items()}
        new_tasks = {
            uav: drop_done_home(self.docks, self.monitor, uav, tasks)
            for uav, tasks in {**computed.tasks, **ordered}.items()
        }
        fleet = self.scenario.fleet
        changed_ids = [
            u.id
            for u in fleet.uavs
            if u.id in self._resend or not same_work(new_tasks.get(u.id, []), self._tasks(u.id))
        ]
        epoch = self.store.counter("epoch")
        changed: list[Plan] = []
        now_s = job.now_s
        if changed_ids:
            try:
                epoch = self.store.next_counter("epoch")
                changed = [
                    Plan(uav_id=u, epoch=epoch, issued_s=now_s, tasks=new_tasks.get(u, []))
                    for u in changed_ids
                ]
                self.store.save_plans(changed)
            except StoreUnavailable:
                self.live.invalidate("a plan the store could not keep")  # not adopted
                raise
            for plan in changed:  # every plan out first: the events' disk sync waits
                self._hold(plan)
                if self.monitor.available(plan.uav_id) or plan.uav_id in self._resend:
                    self.send(plan)
                    self.stats.plans_sent += 1
            with self.events.batch():
                for plan in changed:
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
        if computed.candidate is None:
            if computed.incremental:
                self.stats.incremental += 1
            else:
                self.stats.rebuilds += 1
            self._attempts = 0  # a new state: improvement may try again
            self._restart = False
            self.objective = self.live.objective()
            self.best_objective = self.objective
        if not changed:  # counted in /metrics, not worth an event
            self.stats.unchanged += 1
        else:
            self.events.emit(
                EventKind.REPLAN,
                epoch=epoch,
                detail=f"{job.reason}; {len(changed)} plan(s) changed in "
                f"{elapsed * 1e3:.1f} ms ({computed.how})",
            )
        action_events = placement_events(job.records, new_tasks, result)
        self.waiting = {u.action_id for u in result.unplaced}
        return ReplanOutcome(epoch, changed, action_events, elapsed)

    # -- improvement ------------------------------------------------------------

    def wants_improvement(self) -> bool:
        """Whether an improvement attempt is due on the current state."""
        s = self.improve_settings
        return (
            s.enabled
            and self._attempts < s.attempts
            and self.live.session is not None
            and not self.live.stale
        )

    def prepare_improvement(self, records: list[ActionRecord], now_s: float) -> ReplanJob:
        """An improvement attempt's inputs (on the loop): the tasks frozen now."""
        job = self.prepare(records, now_s, "improvement")
        job.frozen = self._frozen(now_s)
        return job

    def _frozen(self, now_s: float) -> dict[str, list]:
        """The tasks an improvement must keep: those started or starting
        within the freeze horizon, of every UAV that has begun its plan (is
        in the air or executing a task). A UAV still idle on its pad has
        done nothing a changed plan would undo, so its plan stays open."""
        begun = {
            uav: plan.tasks
            for uav, plan in self.plans.items()
            if (status := self.monitor.status(uav)) is not None
            and (status.task_id is not None or self._airborne(uav))
        }
        return frozen_tasks(begun, now_s, self.improve_settings.freeze_s)

    def _airborne(self, uav_id: str) -> bool:
        telemetry = self.monitor.telemetry(uav_id)
        return telemetry is not None and telemetry.flight_state in AIRBORNE

    def improve(
        self, job: ReplanJob, should_stop: Callable[[], bool] = lambda: False
    ) -> Computed | None:
        """Try to improve the live plan (pure: worker thread; ``adopt`` commits)."""
        s = self.improve_settings
        started = time.perf_counter()
        frozen = frozen_parts(job.frozen or {})
        restart = self._restart and self.live.can_restart(frozen)
        candidate = self.live.improve(
            s.rounds, s.seed + self._attempts, frozen, should_stop, restart=restart
        )
        if candidate is None:
            return None
        tasks = self._wire(candidate.plan, job, candidate.base_s)
        return Computed(
            job,
            tasks,
            result=candidate.plan,
            elapsed_s=time.perf_counter() - started,
            candidate=candidate,
        )

    def adopt(self, computed: Computed | None, interrupted: bool = False) -> ReplanOutcome | None:
        """The hysteresis (on the loop): adopt an improved plan only if it is
        better by the margin and keeps every frozen task; else restore."""
        if computed is None or computed.candidate is None:
            if interrupted:
                self.stats.improvements_interrupted += 1
            else:
                self._attempts = self.improve_settings.attempts  # nothing to improve
            return None
        candidate, job = computed.candidate, computed.job
        self.stats.improvements_tried += 1
        self._attempts += 1
        if job.version != self.version:
            candidate.restore()
            self.stats.improvements_interrupted += 1
            return None
        if self.best_objective is None or candidate.after < self.best_objective:
            self.best_objective = candidate.after
        s = self.improve_settings
        frozen = self._frozen(job.now_s)
        ok, why = accept(candidate.before, candidate.after, frozen, computed.tasks, s.margin)
        if not ok:
            candidate.restore()
            self.stats.improvements_rejected += 1
            best = self.live.kept_objective() or candidate.before
            gaining = better_by(best, candidate.after, CONVERGED)
            if not freeze_broken(frozen, computed.tasks):
                self.live.keep(candidate)  # later attempts go on from the best: gains add up
            # a search that stopped gaining starts again from another construction;
            # when none is left (or the plan is flying) the state is left alone
            self._restart = not gaining
            if not gaining and not self.live.can_restart(frozen_parts(frozen)):
                self._attempts = s.attempts
            log.debug("improvement rejected: %s", why)
            return None
        self.live.take(candidate)
        computed.job = dataclasses.replace(job, reason=f"improvement: {why}")
        outcome = self.commit(computed)
        self.stats.improvements_adopted += 1
        self.objective = candidate.after
        self.improved_s = job.now_s
        return outcome

    def _tasks(self, uav_id: str) -> list:
        plan = self.plans.get(uav_id)
        return plan.tasks if plan else []
